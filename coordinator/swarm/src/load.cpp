#include "oscar/swarm/load.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace oscar::swarm {

Load compute_load(const Trajectory& trajectory, const std::vector<Job>& jobs, double max_speed,
                  double t0, double t1) {
  if (!std::isfinite(t0) || !std::isfinite(t1) || t0 >= t1) {
    throw std::invalid_argument(
        fmt::format("load: need a finite interval t0 < t1, got [{}, {}]", t0, t1));
  }
  if (!(max_speed > 0)) throw std::invalid_argument("load: max_speed must be > 0");
  const double dur = t1 - t0;
  Load load;
  for (const auto& j : jobs) {  // jobs of one node never overlap
    load.job += std::max(0.0, std::min(j.end(), t1) - std::max(j.start, t0));
  }
  double driven = 0;
  const auto& p = trajectory.points();
  for (std::size_t i = 1; i < p.size(); ++i) {
    const double dt = p[i].t - p[i - 1].t;
    const double ds = std::hypot(p[i].x - p[i - 1].x, p[i].y - p[i - 1].y);
    if (dt <= 0 || ds <= 0) continue;
    const double overlap = std::max(0.0, std::min(p[i].t, t1) - std::max(p[i - 1].t, t0));
    load.motion += overlap;
    driven += ds * overlap / dt;  // constant speed within a segment
  }
  load.job /= dur;
  load.motion /= dur;
  load.stationary = std::max(0.0, 1 - load.job - load.motion);
  load.total = load.job + load.motion;
  load.velocity = driven / (max_speed * dur);
  return load;
}

}  // namespace oscar::swarm
