#include "svg.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <limits>

#include "oscar/swarm/forbidden_regions.hpp"

namespace oscar::swarm::tools {

namespace {

constexpr std::array<const char*, 8> kColours{"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                              "#ff7f0e", "#17becf", "#8c564b", "#e377c2"};

struct Frame {
  double x0 = std::numeric_limits<double>::max(), y0 = x0, x1 = -x0, y1 = -x0;
  void add(double x, double y) {
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x);
    y1 = std::max(y1, y);
  }
  double scale() const { return 760.0 / std::max({x1 - x0, y1 - y0, 1e-9}); }
  double sx(double x) const { return 20 + (x - x0) * scale(); }
  double sy(double y) const { return 20 + (y1 - y) * scale(); }  // y up
};

std::string polygon(const Frame& f, const Polygon& p, const std::string& style) {
  std::string pts;
  for (const auto& v : vertices(p)) pts += fmt::format("{:.2f},{:.2f} ", f.sx(v.x()), f.sy(v.y()));
  return fmt::format("<polygon points=\"{}\" {}/>\n", pts, style);
}

std::string header(const std::string& title) {
  return fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"800\" height=\"820\" "
      "font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"800\" height=\"820\" "
      "fill=\"white\"/>\n<text x=\"20\" y=\"814\">{}</text>\n",
      title);
}

}  // namespace

std::string world_svg(const Scheduler& s) {
  Frame f;
  for (const auto& p : s.world().static_obstacles) {
    for (const auto& v : vertices(p)) f.add(v.x(), v.y());
  }
  for (const auto& o : s.world().dynamic_obstacles) {
    for (const auto& w : o.trajectory.points()) f.add(w.x, w.y);
  }
  for (const auto& id : s.node_ids()) {
    for (const auto& w : s.trajectory(id).points()) f.add(w.x, w.y);
  }
  std::string out = header(
      "oscar swarm plan: static (grey), moving obstacles (orange, dashed), "
      "node paths (colour), jobs (dots)");
  for (const auto& p : s.world().static_obstacles)
    out += polygon(f, p, "fill=\"#bbb\" stroke=\"#666\"");
  for (const auto& o : s.world().dynamic_obstacles) {
    const auto& pts = o.trajectory.points();
    out += polygon(f, translate(o.shape, pts.front().x, pts.front().y),
                   "fill=\"#fdb\" stroke=\"#f80\" fill-opacity=\"0.6\"");
    std::string line;
    for (const auto& w : pts) line += fmt::format("{:.2f},{:.2f} ", f.sx(w.x), f.sy(w.y));
    out += fmt::format(
        "<polyline points=\"{}\" fill=\"none\" stroke=\"#f80\" stroke-dasharray=\"5,4\"/>\n", line);
  }
  std::size_t k = 0;
  for (const auto& id : s.node_ids()) {
    const char* colour = kColours[k++ % kColours.size()];
    std::string line;
    for (const auto& w : s.trajectory(id).points())
      line += fmt::format("{:.2f},{:.2f} ", f.sx(w.x), f.sy(w.y));
    out += fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>\n",
                       line, colour);
    const auto& start = s.trajectory(id).points().front();
    out += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" fill=\"{}\">{}</text>\n", f.sx(start.x) + 4,
                       f.sy(start.y) - 4, colour, id);
    for (const auto& j : s.jobs(id)) {
      out += fmt::format("<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"4\" fill=\"{}\"/>\n", f.sx(j.x),
                         f.sy(j.y), colour);
      out += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\">{} @{:.1f}</text>\n", f.sx(j.x) + 5,
                         f.sy(j.y) + 12, j.id, j.start);
    }
  }
  return out + "</svg>\n";
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
  const double kx = 760.0 / std::max(f.x1 - f.x0, 1e-9);
  const double ky = 760.0 / std::max(f.y1 - f.y0, 1e-9);
  auto X = [&](double v) { return 20 + (v - f.x0) * kx; };
  auto Y = [&](double v) { return 780 - (v - f.y0) * ky; };
  std::string out =
      header(fmt::format("s-t diagram of {}: s 0..{:.2f} m (right), t {:.1f}..{:.1f} s (up); "
                         "forbidden regions grey, profile red",
                         node, arc, f.y0, f.y1));
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
