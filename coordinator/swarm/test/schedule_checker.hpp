#pragma once
// An independent checker for schedules: its own plain geometry (no Boost.Geometry, nothing from
// the planner's sources), exact by piecewise-linear relative motion. Used by the property test.

#include <array>
#include <map>
#include <string>
#include <vector>

namespace oscar::swarm::check {

using Xy = std::array<double, 2>;
using Xyt = std::array<double, 3>;

struct Body {
  std::string name;
  std::vector<Xy> shape;        // polygon relative to the trajectory point; empty = a point
  double radius = 0;            // clearance required around the shape
  std::vector<Xyt> trajectory;  // piecewise linear
  bool forever = false;         // stays at the last point after the trajectory ends
  double max_speed = 0;         // 0 = not checked
};

struct JobRecord {
  std::string id, node;
  Xy at;
  double start, duration;
  std::vector<Xy> area;
  double earliest_start, latest_finish;
};

/// Collects every violation as a readable line.
class Checker {
 public:
  std::vector<std::string> violations;

  void static_clearance(const Body& node, const std::vector<std::vector<Xy>>& statics);
  void pair_clearance(const Body& a, const Body& b, double t_end);
  void speed(const Body& node);
  void job(const Body& node, const JobRecord& j);
  void no_overlap(const std::vector<JobRecord>& jobs_of_one_node);
  /// Same positions before t_frozen.
  void unchanged_before(const std::string& name, const std::vector<Xyt>& before,
                        const std::vector<Xyt>& after, double t_frozen);
};

Xy position(const std::vector<Xyt>& trajectory, double t);
bool inside_polygon(const Xy& p, const std::vector<Xy>& polygon);  // open interior
double segment_polygon_distance(const Xy& a, const Xy& b, const std::vector<Xy>& polygon);

}  // namespace oscar::swarm::check
