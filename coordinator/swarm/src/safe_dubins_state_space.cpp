#include "safe_dubins_state_space.hpp"

#include <ompl/base/spaces/SE2StateSpace.h>

#include <fmt/format.h>
#include <cmath>
#include <numbers>

namespace oscar::swarm {

namespace ob = ompl::base;

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
// OMPL 1.5.2 rounds turns up to 5e-7 rad short of a full turn and tolerates a miss of 2e-6 turning
// radii; the margins below are generous on both.
constexpr double kRoundingBand = 1e-6;    // rad
constexpr double kMissTolerance = 2e-7;   // turning radii
constexpr double kOmplCoincident = 1e-6;  // OMPL's DUBINS_EPS: closer poses get no words
// Nudges of the two headings (rad): a turn usually moves with one heading or both at about the
// same rate, but a turn next to a loop may move a hundred times slower.
constexpr double kNudges[] = {3e-6, 3e-5, 3e-4};
constexpr double kNudgeDirections[][2] = {{1, -1}, {-1, 1}, {1, 1}, {-1, -1},
                                          {1, 0},  {-1, 0}, {0, 1}, {0, -1}};

struct Xy {
  double x, y;
};

double angle(const Xy& a, const Xy& b) { return std::atan2(b.y - a.y, b.x - a.x); }
double squared_distance(const Xy& a, const Xy& b) {
  return (b.x - a.x) * (b.x - a.x) + (b.y - a.y) * (b.y - a.y);
}

// An angle in [0, 2π) as OMPL 1.5.2 reduces it: a hair below 0 or below a full turn becomes 0.
double reduce_like_ompl(double a) {
  if (a < 0 && a > -1e-7) return 0;
  const double r = a - kTwoPi * std::floor(a / kTwoPi);
  return kTwoPi - r < 5e-7 ? 0 : r;
}

// True if OMPL would round this turn (radians, unreduced) and miss by more than the tolerance,
// `lever` being the length that carries the angle error to the end (turning radii).
bool rounded_badly(double turn, double lever) {
  const double short_of_full = -std::remainder(turn, kTwoPi);
  return short_of_full > 0 && short_of_full < kRoundingBand &&
         short_of_full * lever > kMissTolerance;
}

// Calls visit(turn, middle) for the first and last turn of every Dubins word OMPL computes, and
// the word's middle part, all in turning radii, in OMPL's frame (Shkel and Lumelsky): start at the
// origin with heading alpha, goal at (d, 0) with heading beta. A turning circle's centre lies one
// radius to the left or right of its pose.
template <class Visit>
void for_each_outer_turn(double d, double alpha, double beta, Visit&& visit) {
  const double sa = std::sin(alpha), ca = std::cos(alpha), sb = std::sin(beta), cb = std::cos(beta);
  const Xy left_a{-sa, ca}, right_a{sa, -ca}, left_b{d - sb, cb}, right_b{d + sb, -cb};
  for (const double s : {1.0, -1.0}) {  // words that turn left first, then right first
    const Xy& start = s > 0 ? left_a : right_a;
    const Xy& same = s > 0 ? left_b : right_b;
    const Xy& other = s > 0 ? right_b : left_b;
    // LSL, RSR: the straight part runs parallel to the line between the centres.
    const double direction = angle(start, same);
    const double between = std::sqrt(squared_distance(start, same));
    visit(s * (direction - alpha), between);
    visit(s * (beta - direction), between);
    // LSR, RSL: the straight part crosses that line, if the circles are apart.
    const double apart = squared_distance(start, other) - 4;
    if (apart > -kRoundingBand) {
      const double p = std::sqrt(std::max(apart, 0.0));
      const double crossing = angle(start, other) - std::atan2(-2 * s, p);
      visit(s * (crossing - alpha), p);
      visit(s * (crossing - beta), p);
    }
    // LRL, RLR: a third circle touches both, if they are close.
    const double c = 1 - between * between / 8;
    if (std::abs(c) <= 1) {
      const double p = kTwoPi - std::acos(c);
      const double t = s * (direction - alpha) + p / 2;
      visit(t, p);
      visit(s * (beta - alpha) - t + p, p);
    }
  }
}

// True if OMPL 1.5.2's Dubins code could fail its assertion for this pair.
bool ompl_would_abort(const ob::State* a, const ob::State* b, double radius) {
  const auto* s1 = a->as<ob::SE2StateSpace::StateType>();
  const auto* s2 = b->as<ob::SE2StateSpace::StateType>();
  const double dx = s2->getX() - s1->getX(), dy = s2->getY() - s1->getY();
  const double d = std::sqrt(dx * dx + dy * dy) / radius;  // as OMPL computes it
  const double line = std::atan2(dy, dx);
  // Reduced like OMPL: a heading a hair short of the line counts as on it.
  const double alpha = reduce_like_ompl(s1->getYaw() - line);
  const double beta = reduce_like_ompl(s2->getYaw() - line);
  if (d < kOmplCoincident && std::abs(alpha - beta) < kOmplCoincident) {
    return false;  // OMPL takes the pair as one pose and computes no words
  }
  bool abort = false;
  for_each_outer_turn(d, alpha, beta, [&](double turn, double middle) {
    abort = abort || rounded_badly(turn, middle + 4);  // 4: the two radii of a crossing or a loop
  });
  return abort;
}

// Copies of a pair with the headings turned apart until OMPL can take them.
class NudgedPair {
 public:
  NudgedPair(const ob::StateSpace& space, const ob::State* a, const ob::State* b, double radius)
      : space_(space), a_(space.cloneState(a)), b_(space.cloneState(b)) {
    const double yaw_a = a->as<ob::SE2StateSpace::StateType>()->getYaw();
    const double yaw_b = b->as<ob::SE2StateSpace::StateType>()->getYaw();
    for (const double nudge : kNudges) {
      for (const auto& direction : kNudgeDirections) {
        a_->as<ob::SE2StateSpace::StateType>()->setYaw(yaw_a + direction[0] * nudge);
        b_->as<ob::SE2StateSpace::StateType>()->setYaw(yaw_b + direction[1] * nudge);
        if (!ompl_would_abort(a_, b_, radius)) return;
      }
    }
    free();
    throw UnsafeDubinsPair(fmt::format(
        "Dubins pair ({}, {}, {}) → ({}, {}, {}): OMPL 1.5.2 would fail its assertion for it "
        "and for every nudged pair",
        a->as<ob::SE2StateSpace::StateType>()->getX(),
        a->as<ob::SE2StateSpace::StateType>()->getY(), yaw_a,
        b->as<ob::SE2StateSpace::StateType>()->getX(),
        b->as<ob::SE2StateSpace::StateType>()->getY(), yaw_b));
  }
  ~NudgedPair() { free(); }
  NudgedPair(const NudgedPair&) = delete;
  NudgedPair& operator=(const NudgedPair&) = delete;

  const ob::State* a() const { return a_; }
  const ob::State* b() const { return b_; }

 private:
  void free() {
    space_.freeState(a_);
    space_.freeState(b_);
    a_ = b_ = nullptr;
  }

  const ob::StateSpace& space_;
  ob::State* a_;
  ob::State* b_;
};

}  // namespace

SafeDubinsStateSpace::SafeDubinsStateSpace(double turning_radius_m)
    : DubinsStateSpace(turning_radius_m) {}

double SafeDubinsStateSpace::distance(const ob::State* a, const ob::State* b) const {
  if (!ompl_would_abort(a, b, rho_)) return DubinsStateSpace::distance(a, b);
  const NudgedPair nudged(*this, a, b, rho_);
  return DubinsStateSpace::distance(nudged.a(), nudged.b());
}

void SafeDubinsStateSpace::interpolate(const ob::State* from, const ob::State* to, double t,
                                       bool& firstTime, DubinsPath& path, ob::State* state) const {
  // A cached word is that of a safe pair; at the ends OMPL copies a pose and computes no words.
  if (!firstTime || t <= 0 || t >= 1 || !ompl_would_abort(from, to, rho_)) {
    DubinsStateSpace::interpolate(from, to, t, firstTime, path, state);
    return;
  }
  const NudgedPair nudged(*this, from, to, rho_);
  bool uncached = true;
  DubinsPath word;
  DubinsStateSpace::interpolate(nudged.a(), nudged.b(), t, uncached, word, state);
}

}  // namespace oscar::swarm
