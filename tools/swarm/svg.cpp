#include "svg.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "oscar/swarm/forbidden_regions.hpp"

namespace oscar::swarm::tools {

namespace {

constexpr std::array<const char*, 8> kColours{"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                              "#ff7f0e", "#17becf", "#8c564b", "#e377c2"};

// The plot area of both pictures: 800x820 pixels, axes on the left and at the bottom.
constexpr double kLeft = 60, kTop = 20, kWidth = 720, kHeight = 720;

// World coordinates to pixels, one scale for both axes (metres stay square), y up.
struct Frame {
  double x0 = std::numeric_limits<double>::max(), y0 = x0, x1 = -x0, y1 = -x0;
  void add(double x, double y) {
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x);
    y1 = std::max(y1, y);
  }
  void add(const Polygon& p, double dx = 0, double dy = 0) {
    for (const auto& v : vertices(p)) add(v.x() + dx, v.y() + dy);
  }
  double scale() const {
    return std::min(kWidth / std::max(x1 - x0, 1e-9), kHeight / std::max(y1 - y0, 1e-9));
  }
  double sx(double x) const { return kLeft + (x - x0) * scale(); }
  double sy(double y) const { return kTop + (y1 - y) * scale(); }
};

// A round step giving 5-16 ticks over `range`: 1, 2 or 5 times a power of ten.
double tick_step(double range) {
  const double raw = std::max(range, 1e-9) / 8;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0}) {
    if (m * power >= raw) return m * power;
  }
  return 10 * power;
}

// Axis lines with ticks and their values from `lo` to `hi`; `to_px` maps a value to pixels.
std::string x_axis(double lo, double hi, double y_px, const std::function<double(double)>& to_px,
                   const std::string& label) {
  std::string out = fmt::format(
      "<line x1=\"{:.2f}\" y1=\"{:.2f}\" x2=\"{:.2f}\" y2=\"{:.2f}\" stroke=\"#333\"/>\n",
      to_px(lo), y_px, to_px(hi), y_px);
  const double step = tick_step(hi - lo);
  for (double v = std::ceil(lo / step) * step; v <= hi + step * 1e-6; v += step) {
    out += fmt::format(
        "<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{0:.2f}\" y2=\"{2:.2f}\" stroke=\"#333\"/>"
        "<text x=\"{0:.2f}\" y=\"{3:.2f}\" text-anchor=\"middle\">{4:g}</text>\n",
        to_px(v), y_px, y_px + 5, y_px + 17, std::abs(v) < step * 1e-6 ? 0.0 : v);
  }
  return out + fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" text-anchor=\"middle\">{}</text>\n",
                           (to_px(lo) + to_px(hi)) / 2, y_px + 32, label);
}

std::string y_axis(double lo, double hi, double x_px, const std::function<double(double)>& to_px,
                   const std::string& label) {
  std::string out = fmt::format(
      "<line x1=\"{:.2f}\" y1=\"{:.2f}\" x2=\"{:.2f}\" y2=\"{:.2f}\" stroke=\"#333\"/>\n", x_px,
      to_px(lo), x_px, to_px(hi));
  const double step = tick_step(hi - lo);
  for (double v = std::ceil(lo / step) * step; v <= hi + step * 1e-6; v += step) {
    out += fmt::format(
        "<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{2:.2f}\" y2=\"{1:.2f}\" stroke=\"#333\"/>"
        "<text x=\"{3:.2f}\" y=\"{4:.2f}\" text-anchor=\"end\">{5:g}</text>\n",
        x_px, to_px(v), x_px - 5, x_px - 7, to_px(v) + 4, std::abs(v) < step * 1e-6 ? 0.0 : v);
  }
  return out + fmt::format(
                   "<text x=\"14\" y=\"{0:.2f}\" text-anchor=\"middle\" transform=\"rotate(-90 14 "
                   "{0:.2f})\">{1}</text>\n",
                   (to_px(lo) + to_px(hi)) / 2, label);
}

// Places labels where they overlap no label placed before (tries offsets around the point).
class LabelPlacer {
 public:
  std::string place(double x, double y, const std::string& text, const std::string& style = "") {
    const double w = 6.2 * static_cast<double>(text.size()), h = 12;
    const std::pair<double, double> offsets[] = {{5, 12}, {5, -5},  {-5 - w, 12}, {-5 - w, -5},
                                                 {5, 25}, {5, -18}, {-5 - w, 25}, {-5 - w, -18}};
    std::pair<double, double> at = offsets[0];
    for (const auto& o : offsets) {
      if (free(x + o.first, y + o.second - h, w, h)) {
        at = o;
        break;
      }
    }
    boxes_.push_back({x + at.first, y + at.second - h, w, h});
    return fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\"{}>{}</text>\n", x + at.first, y + at.second,
                       style, text);
  }

 private:
  struct Box {
    double x, y, w, h;
  };
  bool free(double x, double y, double w, double h) const {
    return std::none_of(boxes_.begin(), boxes_.end(), [&](const Box& b) {
      return x < b.x + b.w && b.x < x + w && y < b.y + b.h && b.y < y + h;
    });
  }
  std::vector<Box> boxes_;
};

std::string polygon(const Frame& f, const Polygon& p, const std::string& style) {
  std::string pts;
  for (const auto& v : vertices(p)) pts += fmt::format("{:.2f},{:.2f} ", f.sx(v.x()), f.sy(v.y()));
  return fmt::format("<polygon points=\"{}\" {}/>\n", pts, style);
}

// The picture's frame, `height` pixels high, with its caption (one text line per entry) at the
// bottom.
std::string header(const std::vector<std::string>& caption, double height = 820) {
  std::string out = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"800\" height=\"{0:.0f}\" "
      "font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"800\" height=\"{0:.0f}\" "
      "fill=\"white\"/>\n",
      height);
  double y = height - 6 - 14 * static_cast<double>(caption.size() - 1);
  for (const auto& line : caption) {
    out += fmt::format("<text x=\"20\" y=\"{:.0f}\">{}</text>\n", y, line);
    y += 14;
  }
  return out;
}

}  // namespace

std::string world_svg(const WorldPicture& picture) {
  Frame f;
  for (const auto& p : picture.static_obstacles) f.add(p);
  for (const auto& o : picture.moving_obstacles) {
    for (const auto& p : o.path) f.add(o.shape, p.x(), p.y());  // the whole shape
  }
  for (const auto& r : picture.robots) {
    for (const auto& p : r.path) f.add(p.x(), p.y());
    if (r.now) {
      f.add(r.now->x() - r.radius, r.now->y() - r.radius);
      f.add(r.now->x() + r.radius, r.now->y() + r.radius);
    }
  }
  // As high as the world needs at the scale its width allows: the axis, its labels, the caption.
  const double plot_height = (f.y1 - f.y0) * f.scale();
  std::string out = header(
      picture.caption, kTop + plot_height + 50 + 14 * static_cast<double>(picture.caption.size()));
  out += x_axis(
      f.x0, f.x1, f.sy(f.y0) + 8, [&](double x) { return f.sx(x); }, "x [m]");
  out += y_axis(
      f.y0, f.y1, f.sx(f.x0) - 8, [&](double y) { return f.sy(y); }, "y [m]");
  LabelPlacer labels;
  for (const auto& p : picture.static_obstacles)
    out += polygon(f, p, "fill=\"#bbb\" stroke=\"#666\"");
  for (const auto& o : picture.moving_obstacles) {
    out += polygon(f, translate(o.shape, o.now.x(), o.now.y()),
                   "fill=\"#fdb\" stroke=\"#f80\" fill-opacity=\"0.6\"");
    std::string line;
    for (const auto& p : o.path) line += fmt::format("{:.2f},{:.2f} ", f.sx(p.x()), f.sy(p.y()));
    out += fmt::format(
        "<polyline points=\"{}\" fill=\"none\" stroke=\"#f80\" stroke-dasharray=\"5,4\"/>\n", line);
  }
  std::size_t k = 0;
  for (const auto& r : picture.robots) {
    const char* colour = kColours[k++ % kColours.size()];
    std::string line;
    for (const auto& p : r.path) line += fmt::format("{:.2f},{:.2f} ", f.sx(p.x()), f.sy(p.y()));
    if (!line.empty()) {
      out +=
          fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>\n",
                      line, colour);
    }
    if (r.now) {
      out += fmt::format(
          "<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"{:.2f}\" fill=\"{}\" stroke=\"#333\"/>\n",
          f.sx(r.now->x()), f.sy(r.now->y()), std::max(r.radius * f.scale(), 3.0),
          r.broken ? "#f00" : colour);
    }
    const auto label_at = r.now            ? std::optional<Point>(*r.now)
                          : r.path.empty() ? std::nullopt
                                           : std::optional<Point>(r.path.front());
    if (label_at) {
      out +=
          labels.place(f.sx(label_at->x()), f.sy(label_at->y()),
                       r.broken ? r.id + " (broken)" : r.id, fmt::format(" fill=\"{}\"", colour));
    }
    for (const auto& j : r.jobs) {
      out += fmt::format("<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"4\" fill=\"{}\"/>\n",
                         f.sx(j.at.x()), f.sy(j.at.y()), colour);
      out += labels.place(f.sx(j.at.x()), f.sy(j.at.y()), j.label);
    }
  }
  return out + "</svg>\n";
}

std::string world_svg(const Scheduler& s) {
  WorldPicture picture;
  picture.caption = {
      "oscar swarm plan: static obstacles (grey), moving obstacles at their start and their path "
      "(orange, dashed),",
      "node paths (colour, labelled at their start), jobs (dots: id @ start time in s)"};
  picture.static_obstacles = s.world().static_obstacles;
  for (const auto& o : s.world().dynamic_obstacles) {
    const auto& pts = o.trajectory.points();
    WorldPicture::MovingObstacle m{o.shape, {}, Point(pts.front().x, pts.front().y)};
    for (const auto& w : pts) m.path.emplace_back(w.x, w.y);
    picture.moving_obstacles.push_back(std::move(m));
  }
  for (const auto& id : s.node_ids()) {
    WorldPicture::Robot r{id, {}, {}, std::nullopt, s.node(id).radius_m, false};
    for (const auto& w : s.trajectory(id).points()) r.path.emplace_back(w.x, w.y);
    for (const auto& j : s.jobs(id)) {
      r.jobs.push_back({Point(j.x, j.y), fmt::format("{} @{:.1f}", j.id, j.start)});
    }
    picture.robots.push_back(std::move(r));
  }
  return world_svg(picture);
}

std::string st_svg(const Scheduler& s, const std::string& node) {
  const auto& spec = s.node(node);
  const auto& traj = s.trajectory(node);
  std::vector<Point> path;
  std::vector<Point> profile;  // (s, t)
  double arc = 0;
  for (const auto& w : traj.points()) {
    const Point p(w.x, w.y);
    if (!path.empty()) arc += distance(path.back(), p);
    if (path.empty() || distance(path.back(), p) > kEpsilon) path.push_back(p);
    profile.emplace_back(arc, w.t);
  }
  const double t_end = std::max(traj.end_time(), traj.start_time() + 1);
  std::vector<MovingObstacle> obstacles;
  for (const auto& o : s.world().dynamic_obstacles)
    obstacles.push_back({inflate(o.shape, spec.radius_m), o.trajectory});
  for (const auto& id : s.node_ids()) {
    if (id == node) continue;
    Trajectory t = s.trajectory(id);
    const auto last = t.points().back();
    t.append({last.x, last.y, t_end});
    obstacles.push_back({disc_polygon(spec.radius_m + s.node(id).radius_m), t});
  }
  std::vector<Polygon> regions;
  if (path.size() >= 2) {
    for (const auto& o : obstacles) {
      for (auto& r : compute_forbidden_regions(path, o, traj.start_time(), t_end).regions)
        regions.push_back(r);
    }
  }
  Frame f;
  f.add(0, traj.start_time());
  f.add(std::max(arc, 1e-3), t_end);
  // s horizontally, t vertically; scale axes independently.
  const double kx = kWidth / std::max(f.x1 - f.x0, 1e-9);
  const double ky = kHeight / std::max(f.y1 - f.y0, 1e-9);
  auto X = [&](double v) { return kLeft + (v - f.x0) * kx; };
  auto Y = [&](double v) { return kTop + kHeight - (v - f.y0) * ky; };
  std::string out =
      header({fmt::format("s-t diagram of {}: forbidden regions of the other nodes and "
                          "moving obstacles on its path (grey), its profile (red)",
                          node)});
  out += x_axis(f.x0, f.x1, Y(f.y0) + 8, X, "s along the path [m]");
  out += y_axis(f.y0, f.y1, X(f.x0) - 8, Y, "t [s]");
  for (const auto& r : regions) {
    std::string pts;
    for (const auto& v : vertices(r)) pts += fmt::format("{:.2f},{:.2f} ", X(v.x()), Y(v.y()));
    out += fmt::format("<polygon points=\"{}\" fill=\"#999\" stroke=\"#555\"/>\n", pts);
  }
  std::string line;
  for (const auto& p : profile) line += fmt::format("{:.2f},{:.2f} ", X(p.x()), Y(p.y()));
  out += fmt::format(
      "<polyline points=\"{}\" fill=\"none\" stroke=\"#d62728\" stroke-width=\"2\"/>\n", line);
  return out + "</svg>\n";
}

}  // namespace oscar::swarm::tools
