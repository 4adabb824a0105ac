#pragma once

#include <cstdint>
#include <vector>

#include <oscar/time.hpp>

namespace oscar::modules {

/// A place and the time the robot is there (metres; ns since the epoch).
struct TimedPoint {
  double x = 0;
  double y = 0;
  Stamp t = 0;
  bool operator==(const TimedPoint&) const = default;
};

struct Place {
  double x = 0;
  double y = 0;
};

/// Where a robot is at a time and how it moves there.
struct Motion {
  double x = 0;
  double y = 0;
  double heading =
      0;  ///< rad, counterclockwise from +x: the direction of motion, kept while standing
  double speed = 0;  ///< m/s
};

/// The place on the polyline `points` (times non-decreasing, not empty) at time t: interpolated
/// linearly, the first point before it starts and the last after it ends.
Place place_at(const std::vector<TimedPoint>& points, Stamp t);

/// A robot's committed trajectory: piecewise linear in x × y × t with non-decreasing times in ns
/// since the epoch. The robot is at the first point before it and stays at the last point for
/// good. Sections are spliced in as the swarm planner splices them (coordinator/swarm,
/// Trajectory::spliced), and each section remembers the transaction that brought it.
class PilotTrajectory {
 public:
  /// A robot standing at (x, y), facing `heading`, for good.
  PilotTrajectory(double x, double y, double heading);

  /// Place, heading and speed at time t. At a vertex the segment that starts there counts.
  Motion at(Stamp t) const;

  /// The transaction whose section holds time t, or 0. A closed section holds [lo, hi]; an
  /// open-ended one holds [lo, its last waypoint] (after that the robot stands: it drives
  /// nothing). Where two sections touch, the later spliced one holds the shared instant.
  std::uint64_t transaction_at(Stamp t) const;

  /// Replaces the span [lo, hi] (open_end: [lo, forever)) by the section `points`: the
  /// trajectory before lo, the section's place at lo, its points strictly inside the span, then
  /// (closed) its place at hi and the trajectory after hi, or (open end) its last point.
  /// `points` is not empty and its times do not decrease.
  void splice(const std::vector<TimedPoint>& points, Stamp lo, Stamp hi, bool open_end,
              std::uint64_t transaction);

  /// The trajectory from t on: its place at t, then its points after t (the robot stays at the
  /// last one for good).
  std::vector<TimedPoint> from(Stamp t) const;

  /// Forgets what lies wholly before t (the trajectory stays the same from t on).
  void forget_before(Stamp t);

  /// The robot stops at its place at time t and stands there for good, facing as it did.
  void stop_at(Stamp t);

  const std::vector<TimedPoint>& points() const { return points_; }

 private:
  struct Span {
    Stamp lo = 0, hi = 0;
    std::uint64_t transaction = 0;
  };
  double heading_before(std::size_t segment_end) const;

  std::vector<TimedPoint> points_;
  double base_heading_;  // the heading before the first point's moving segments
  std::vector<Span> spans_;
};

}  // namespace oscar::modules
