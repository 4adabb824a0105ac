#pragma once
/// @file Velocity profiles in the s–t plane (seed 002 §4.3.2, §4.3.4, Anhang A.5, A.6).

#include <optional>
#include <vector>

#include "oscar/swarm/geometry.hpp"

namespace oscar::swarm {

/// Plans s(t) along a path of length s_final from (0, t_start), avoiding forbidden regions
/// (seed §4.3.2): a visibility graph in s–t with edges forward in time (eq. 4.12) and no faster
/// than v_max (eq. 4.13). Only forward motion along the path (Δs ≥ 0) is used.
class VelocityPlanner {
 public:
  struct Settings {
    double v_max = 1;             ///< maximum speed (m/s)
    double v_leave = 0;           ///< v_L of §4.3.4: speed after a wait; 0 means v_max
    double wait_threshold_s = 0;  ///< d_th of §4.3.4: shorter waits are not added
  };

  /// Overlapping or edge-sharing regions are merged first (merge_regions), so no profile can run
  /// along a seam between two of them.
  VelocityPlanner(double s_final, double t_start, std::vector<Polygon> regions, Settings settings);

  /// Fixed arrival at (s_final, t_final) (Anhang A.5) with waiting instead of crawling (§4.3.4):
  /// edges cost their driving time, waits cost nothing. Returns (s, t) vertices or nullopt.
  std::optional<std::vector<Point>> fixed_arrival(double t_final) const;

  /// The earliest arrival no later than t_latest (Anhang A.6): phase 1 finds t_min with
  /// max-speed edges to the line s = s_final, phase 2 is fixed_arrival(t_min).
  std::optional<std::vector<Point>> earliest_arrival(double t_latest) const;

  /// True if the s–t segment avoids every region's interior.
  bool free(const Point& a, const Point& b) const;

 private:
  bool edge_ok(const Point& a, const Point& b) const;
  std::vector<Point> corners(double t_max) const;
  bool inside_any(const Point& p) const;  // strictly inside some region

  struct Bounds {
    double s0, t0, s1, t1;
  };

  double s_final_;
  double t_start_;
  std::vector<Polygon> regions_;
  std::vector<Bounds> bounds_;  // of each region, for a cheap rejection in free()
  Settings settings_;
};

}  // namespace oscar::swarm
