#include "schedule_checker.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace oscar::swarm::check {

namespace {

constexpr double kTol = 1e-7;

double dist_point_segment(const Xy& p, const Xy& a, const Xy& b) {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double l2 = dx * dx + dy * dy;
  double u = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0;
  u = std::max(0.0, std::min(1.0, u));
  return std::hypot(p[0] - a[0] - u * dx, p[1] - a[1] - u * dy);
}

double cross(const Xy& o, const Xy& a, const Xy& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

bool segments_cross(const Xy& a, const Xy& b, const Xy& c, const Xy& d) {
  const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

}  // namespace

Xy position(const std::vector<Xyt>& tr, double t) {
  if (t <= tr.front()[2]) return {tr.front()[0], tr.front()[1]};
  for (std::size_t i = 1; i < tr.size(); ++i) {
    if (t <= tr[i][2]) {
      const double span = tr[i][2] - tr[i - 1][2];
      const double u = span > 0 ? (t - tr[i - 1][2]) / span : 1;
      return {tr[i - 1][0] + u * (tr[i][0] - tr[i - 1][0]),
              tr[i - 1][1] + u * (tr[i][1] - tr[i - 1][1])};
    }
  }
  return {tr.back()[0], tr.back()[1]};
}

bool inside_polygon(const Xy& p, const std::vector<Xy>& poly) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    if (dist_point_segment(p, poly[j], poly[i]) < 1e-12) return false;
    if ((poly[i][1] > p[1]) != (poly[j][1] > p[1]) &&
        p[0] < poly[j][0] +
                   (p[1] - poly[j][1]) * (poly[i][0] - poly[j][0]) / (poly[i][1] - poly[j][1])) {
      in = !in;
    }
  }
  return in;
}

double segment_polygon_distance(const Xy& a, const Xy& b, const std::vector<Xy>& poly) {
  if (inside_polygon(a, poly) || inside_polygon(b, poly)) return -1;
  double best = 1e300;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    if (segments_cross(a, b, poly[j], poly[i])) return -1;
    best = std::min({best, dist_point_segment(a, poly[j], poly[i]),
                     dist_point_segment(b, poly[j], poly[i]), dist_point_segment(poly[i], a, b)});
  }
  // A segment through two vertices can pass the interior without crossing an edge properly.
  const Xy mid{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2};
  if (inside_polygon(mid, poly)) return -1;
  return best;
}

void Checker::static_clearance(const Body& n, const std::vector<std::vector<Xy>>& statics) {
  const auto& tr = n.trajectory;
  for (const auto& poly : statics) {
    for (std::size_t i = 0; i < tr.size(); ++i) {
      const Xy a{tr[i][0], tr[i][1]};
      const Xy b = i + 1 < tr.size() ? Xy{tr[i + 1][0], tr[i + 1][1]} : a;
      const double d = segment_polygon_distance(a, b, poly);
      if (d < n.radius - kTol) {
        violations.push_back(n.name + " too close to a static obstacle near t=" + fmt(tr[i][2]) +
                             " (distance " + fmt(d) + ")");
      }
    }
  }
}

void Checker::pair_clearance(const Body& a, const Body& b, double t_end) {
  // Common breakpoints: between them both move linearly, so the relative motion is a segment.
  const double lo = std::max(a.trajectory.front()[2], b.trajectory.front()[2]);
  const double hi = std::min(a.forever ? t_end : a.trajectory.back()[2],
                             b.forever ? t_end : b.trajectory.back()[2]);
  if (hi < lo) return;
  std::vector<double> times{lo, hi};
  for (const auto* body : {&a, &b}) {
    for (const auto& w : body->trajectory) {
      if (w[2] > lo && w[2] < hi) times.push_back(w[2]);
    }
  }
  std::sort(times.begin(), times.end());
  const double need = a.radius + b.radius;
  for (std::size_t k = 0; k + 1 < times.size() || (times.size() == 1 && k == 0); ++k) {
    const double t0 = times[k];
    const double t1 = k + 1 < times.size() ? times[k + 1] : t0;
    // Positions of a relative to b at both ends; b's shape is fixed in b's frame.
    const Xy pa0 = position(a.trajectory, t0), pb0 = position(b.trajectory, t0);
    const Xy pa1 = position(a.trajectory, t1), pb1 = position(b.trajectory, t1);
    const Xy r0{pa0[0] - pb0[0], pa0[1] - pb0[1]};
    const Xy r1{pa1[0] - pb1[0], pa1[1] - pb1[1]};
    double d;
    if (b.shape.empty()) {
      d = dist_point_segment({0, 0}, r0, r1);
    } else {
      d = segment_polygon_distance(r0, r1, b.shape);
    }
    if (d < need - kTol) {
      violations.push_back(a.name + " and " + b.name + " closer than " + fmt(need) + " during [" +
                           fmt(t0) + ", " + fmt(t1) + "] (distance " + fmt(d) + ")");
      return;
    }
  }
}

void Checker::speed(const Body& n) {
  const auto& tr = n.trajectory;
  for (std::size_t i = 1; i < tr.size(); ++i) {
    const double ds = std::hypot(tr[i][0] - tr[i - 1][0], tr[i][1] - tr[i - 1][1]);
    const double dt = tr[i][2] - tr[i - 1][2];
    if (dt < 0 || ds > n.max_speed * dt * (1 + 1e-9) + 1e-9) {
      violations.push_back(n.name + " too fast at t=" + fmt(tr[i - 1][2]) + ": " + fmt(ds) +
                           " m in " + fmt(dt) + " s");
    }
  }
}

void Checker::job(const Body& n, const JobRecord& j) {
  const double end = j.start + j.duration;
  std::vector<double> times{j.start, end};
  for (const auto& w : n.trajectory) {
    if (w[2] > j.start && w[2] < end) times.push_back(w[2]);
  }
  for (double t : times) {
    const Xy p = position(n.trajectory, t);
    if (std::hypot(p[0] - j.at[0], p[1] - j.at[1]) > 1e-7) {
      violations.push_back("job " + j.id + ": " + n.name + " not at its location at t=" + fmt(t));
      break;
    }
  }
  bool in_area = inside_polygon(j.at, j.area);
  for (std::size_t i = 0, k = j.area.size() - 1; i < j.area.size(); k = i++) {
    in_area = in_area || dist_point_segment(j.at, j.area[k], j.area[i]) < 1e-9;
  }
  if (!in_area) violations.push_back("job " + j.id + ": location outside its area");
  if (j.start < j.earliest_start - 1e-9 || end > j.latest_finish + 1e-9) {
    violations.push_back("job " + j.id + ": [" + fmt(j.start) + ", " + fmt(end) +
                         "] outside its window [" + fmt(j.earliest_start) + ", " +
                         fmt(j.latest_finish) + "]");
  }
}

void Checker::no_overlap(const std::vector<JobRecord>& jobs) {
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    for (std::size_t k = i + 1; k < jobs.size(); ++k) {
      const auto& a = jobs[i];
      const auto& b = jobs[k];
      if (a.start < b.start + b.duration - 1e-9 && b.start < a.start + a.duration - 1e-9) {
        violations.push_back("jobs " + a.id + " and " + b.id + " overlap on " + a.node);
      }
    }
  }
}

void Checker::unchanged_before(const std::string& name, const std::vector<Xyt>& before,
                               const std::vector<Xyt>& after, double t_frozen) {
  std::vector<double> times{t_frozen};
  for (const auto* tr : {&before, &after}) {
    for (const auto& w : *tr) {
      if (w[2] < t_frozen) times.push_back(w[2]);
    }
  }
  for (double t : times) {
    if (t < before.front()[2]) continue;
    const Xy p = position(before, t), q = position(after, t);
    if (std::hypot(p[0] - q[0], p[1] - q[1]) > 1e-9) {
      violations.push_back(name + " changed before the frozen horizon " + fmt(t_frozen) +
                           " at t=" + fmt(t));
      return;
    }
  }
}

}  // namespace oscar::swarm::check
