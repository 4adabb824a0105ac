#pragma once
/// @file OMPL's Dubins state space without the assertion failures of OMPL 1.5.2 (internal to
/// DubinsPathFinder; its test includes it).

#include <ompl/base/spaces/DubinsStateSpace.h>

#include <stdexcept>

namespace oscar::swarm {

/// Thrown when no pair near the given one is safe for OMPL's Dubins code (not seen in practice;
/// DubinsPathFinder reports the leg as not found).
class UnsafeDubinsPair : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// OMPL 1.5.2 computes all six Dubins words for every pair of poses (DubinsStateSpace.cpp,
/// dubinsLSL … dubinsLRL). Each word rounds a first or last turn less than 5e-7 rad short of a
/// full turn to no turn, then asserts that the word still reaches the goal within 2e-6 turning
/// radii. The rounding misses by about the rounded angle times the rest of the word, so after a
/// long straight part the assertion fails and the process aborts (Debian builds OMPL with
/// assertions). RRT makes such pairs itself: a pose it steered toward the goal heads almost exactly
/// along a tangent of the goal's turning circle.
///
/// This space hands OMPL such a pair with the two headings turned a few microradians apart, which
/// moves the turns well clear of the rounding; every other pair goes to OMPL unchanged. Poses must
/// be at most about 1e6 turning radii apart (beyond that OMPL's plain rounding errors reach its
/// tolerance).
class SafeDubinsStateSpace : public ompl::base::DubinsStateSpace {
 public:
  explicit SafeDubinsStateSpace(double turning_radius_m);

  using DubinsStateSpace::interpolate;  // the 4-argument one, which calls the one below

  /// @throws UnsafeDubinsPair if no nudged pair is safe either.
  double distance(const ompl::base::State* a, const ompl::base::State* b) const override;

  /// The interpolation all others use (OMPL's DubinsMotionValidator, the default for this space,
  /// calls it directly). A nudged pair's word is not cached in `path`: later calls with the
  /// pair nudge again, so every call interpolates the same curve.
  /// @throws UnsafeDubinsPair if no nudged pair is safe either.
  void interpolate(const ompl::base::State* from, const ompl::base::State* to, double t,
                   bool& firstTime, DubinsPath& path, ompl::base::State* state) const override;
};

}  // namespace oscar::swarm
