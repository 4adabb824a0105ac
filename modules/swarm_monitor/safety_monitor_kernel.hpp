#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <oscar/kernel.hpp>
#include <oscar/swarm_types.hpp>

#include "monitor_geometry.hpp"
#include "monitor_obstacles.hpp"

namespace oscar::modules {

/// An independent safety monitor of the live swarm (modules/swarm_monitor/README.md): at every
/// robot state that arrives it checks that the robot keeps its distance from every other robot,
/// stays out of the static and moving obstacles and works its job at the job's place within the
/// job's window, and publishes each new violation once on `violations`. Its geometry is its own
/// (monitor_geometry.hpp): it is the check on the planner, not a second use of it.
class SafetyMonitor final : public Kernel {
 public:
  struct Params {
    std::string inputs;                ///< "name, name": robot inputs besides the wired ones
    std::string static_obstacles;      ///< YAML: [ [[x, y], ...], ... ]
    std::string moving_obstacles;      ///< YAML: [ {shape: [[x, y], ...], loop: [[x, y, t], ...]} ]
    double distance_tolerance = 1e-3;  ///< m a disc may reach into another or an obstacle
    double job_tolerance = 0.05;       ///< m a working robot may be from its job's place
    std::chrono::nanoseconds max_extrapolation{std::chrono::milliseconds(500)};
    void describe(ParamSpec& spec);
  };

  /// The kinds of violation, in the order the counts list them.
  static constexpr const char* kKinds[] = {"distance", "static_obstacle", "moving_obstacle", "job"};

  /// Parses parameter `inputs`: input names separated by commas.
  /// @throws std::invalid_argument naming the bad entry.
  static std::vector<std::string> parse_inputs(const std::string& text);
  /// Parses parameter `static_obstacles` (YAML text; empty: none).
  /// @throws std::invalid_argument naming the obstacle and the rule it breaks.
  static std::vector<safety::StaticObstacle> parse_static_obstacles(const std::string& text);
  /// Parses parameter `moving_obstacles` (YAML text; empty: none).
  /// @throws std::invalid_argument naming the obstacle and the rule it breaks.
  static std::vector<safety::MovingObstacle> parse_moving_obstacles(const std::string& text);

  /// Declares one RobotState input per input the configuration names and per name in `inputs`,
  /// and command `world`.
  /// @throws std::invalid_argument without any input or on a bad obstacle.
  explicit SafetyMonitor(KernelSetup& setup);
  void process(Cycle& cycle) override;
  /// Checks nothing: publishes a made-up violation (detail "stub mode: ...") at most once a
  /// second, so that a consumer of violations can be tested alone.
  void stub(Cycle& cycle) override;

  /// Violations reported so far of one kind ("distance", ...), or of all kinds.
  std::uint64_t count(const std::string& kind) const;
  std::uint64_t total() const { return total_; }

 private:
  struct Robot {
    std::string input;
    Input<RobotState>* in = nullptr;
  };
  /// Where a robot was at a time: its state, extrapolated there.
  struct Place {
    std::shared_ptr<const RobotState> state;
    safety::Point at;
    double dt_s = 0;  ///< from the state's stamp to the time asked (0: the state itself)
  };
  /// A continuing violation of one pair, obstacle or job, known by its key.
  struct Condition {
    bool active = false;
    Stamp last = 0;  ///< stamp of the last evaluation applied
  };
  struct Finding {
    std::string kind;
    std::vector<std::string> robots;
    std::string job;
    std::string detail;
    safety::Point at;
  };

  /// Command `world`: the coordinator's world replaces all obstacles, those of the parameters
  /// too; a bad one is refused and changes nothing.
  CommandAnswer set_world(const SwarmWorld& world);
  void check(Cycle& cycle, std::size_t robot, const RobotState& state);
  void check_obstacles(Cycle& cycle, std::size_t robot, const RobotState& state);
  std::optional<Place> place_of(std::size_t robot, Stamp t) const;
  /// Applies one evaluation of `key` at time t: reports `finding` if it starts a violation.
  void evaluate(Cycle& cycle, const std::string& key, Stamp t, const CueHeader& header,
                std::optional<Finding> finding);
  void report(Cycle& cycle, const CueHeader& header, Finding finding);

  Params params_;
  std::vector<Robot> robots_;
  safety::Obstacles obstacles_;
  Output<SafetyViolation>& out_;
  std::map<std::string, Condition> conditions_;  // by key
  std::map<std::string, std::uint64_t> counts_;  // by kind
  std::uint64_t total_ = 0;
  std::uint64_t stub_count_ = 0;
  Stamp last_stub_ = 0;
};

}  // namespace oscar::modules
