#pragma once
/// @file A planning problem as read by `oscar swarm plan` (format in docs/swarm.md).

#include <string>

#include <yaml-cpp/yaml.h>
#include <vector>

#include "oscar/swarm/scheduler.hpp"

namespace oscar::swarm {

/// One operation of a problem file.
struct Operation {
  enum class Kind {
    kSchedule,
    kPeriodic,
    kDependent,
    kUnschedule,
    kUnscheduleSet,
    kRemove,
    kRemoveNode,
    kReschedule,
    kCommit,
    kAbort,
    kSetPresent
  };
  Kind kind = Kind::kSchedule;
  std::string name;               ///< the op as written
  JobSpec job;                    ///< schedule, reschedule
  PeriodicSpec periodic;          ///< schedule_periodic
  DependentSpec dependent;        ///< schedule_dependent
  std::string id;                 ///< unschedule, remove
  TransactionId transaction = 0;  ///< commit/abort; 0 = the last open one
  std::string node;               ///< commit/abort of one node; remove_node
  double t = 0;                   ///< set_present
  int line = 0;                   ///< 1-based line in the file
};

/// A place in the problem file (1-based), for messages.
struct FilePosition {
  int line = 0;
  int column = 0;
};

/// A world, nodes, settings and operations.
struct Problem {
  std::string source;  ///< file name for messages
  World world;
  std::vector<NodeSpec> nodes;
  /// Where each of `nodes` is in the file, in the same order (empty if not read from a file).
  std::vector<FilePosition> node_positions;
  SchedulerSettings settings;
  std::vector<Operation> operations;
};

/// Parses a problem from YAML or JSON text and validates it completely before any planning.
/// @throws std::invalid_argument with "source:line:column: what: rule" on bad input.
Problem parse_problem(const std::string& text, const std::string& source);

/// The `world:` of a problem file (static and moving obstacles); also the live swarm's.
/// @throws std::invalid_argument with "source:line:column: what: rule".
World parse_world(const YAML::Node& node, const std::string& source);

/// Operations for a running swarm (`oscar swarm submit`): a list as a problem file's
/// `operations:` with schedule, schedule_periodic, schedule_dependent, unschedule,
/// unschedule_set and reschedule only; ids may name jobs submitted before.
/// @throws std::invalid_argument with "source:line:column: what: rule".
std::vector<Operation> parse_operations(const std::string& text, const std::string& source);

/// One job specification as a problem file writes it (id, area, earliest_start, latest_finish,
/// duration). @throws std::invalid_argument with "source:line:column: what: rule".
JobSpec parse_job(const std::string& text, const std::string& source);

/// Reads and parses a problem file.
/// @throws std::invalid_argument if the file cannot be read or is invalid.
Problem load_problem(const std::string& path);

}  // namespace oscar::swarm
