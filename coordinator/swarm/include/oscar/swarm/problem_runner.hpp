#pragma once
/// @file Runs a Problem's operations on a Scheduler and writes the schedule as JSON.

#include <string>
#include <vector>

#include "oscar/swarm/problem.hpp"
#include "oscar/swarm/scheduler.hpp"

namespace oscar::swarm {

/// What one operation did.
struct OperationOutcome {
  std::string op;
  bool ok = false;
  std::string reason;
  TransactionId transaction = 0;
  std::vector<Job> jobs;
};

/// Runs a problem from scratch.
class ProblemRunner {
 public:
  /// Builds the scheduler and adds the nodes.
  /// @throws std::invalid_argument if a node is invalid or collides, with the node's
  /// "source:line:column" when the problem has its position.
  explicit ProblemRunner(const Problem& problem);

  /// Runs all operations; failures are outcomes, not exceptions.
  void run();

  const Scheduler& scheduler() const { return scheduler_; }
  const std::vector<OperationOutcome>& outcomes() const { return outcomes_; }

  /// The output document of docs/swarm.md: operations, committed jobs and trajectories, each
  /// node's load (seed §4.4) from the present to the end of the last committed job, open
  /// transactions and the world.
  std::string to_json(int indent = 2) const;

 private:
  const Problem& problem_;
  Scheduler scheduler_;
  std::vector<OperationOutcome> outcomes_;
};

}  // namespace oscar::swarm
