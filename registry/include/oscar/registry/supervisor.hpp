#pragma once
/// @file Supervisor: the process side of `oscar-monitor` (docs/boot.md). Starts module processes,
/// captures their output to one log file per module, reports how they end, and stops them in
/// reverse start order. No DDS: the monitor program connects it to the registry.

#include <sys/types.h>

#include <chrono>
#include <csignal>
#include <optional>
#include <string>
#include <vector>

namespace oscar {

struct ProcessExit {
  std::string module;
  unsigned incarnation = 0;
  pid_t pid = 0;
  int exit_code = -1;  ///< -1 when ended by a signal
  int signal = 0;
  std::string last_output;  ///< the last lines the process wrote

  /// "exited with code 3" / "killed by signal 9 (Killed)".
  std::string describe() const;
};

class Supervisor {
 public:
  /// A process it started that has not been reaped yet.
  struct Child {
    std::string module;
    unsigned incarnation = 0;
    pid_t pid = 0;
  };

  /// Module output goes to `<log_dir>/<module>.log` (appended, one header line per start).
  /// Children get `death_signal` when the supervisor's process dies (PR_SET_PDEATHSIG): SIGKILL
  /// for a monitor's modules (they die with their host), SIGTERM for boot's registry and
  /// monitors, so that a killed boot still stops the system in order.
  explicit Supervisor(std::string log_dir, int death_signal = SIGKILL);
  ~Supervisor();  ///< stops whatever still runs
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  /// Starts `argv` (argv[0] looked up on PATH unless it has a '/') with extra "NAME=value"
  /// environment entries. Children die with the supervisor (see the constructor).
  /// @throws std::runtime_error "cannot start <module>: <program>: <reason>" if exec fails.
  pid_t start(const std::string& module, unsigned incarnation, const std::vector<std::string>& argv,
              const std::vector<std::string>& env = {});
  /// Sends a signal to the module's process, if it runs.
  bool signal(const std::string& module, int sig);
  /// Collects processes that ended since the last call (non-blocking).
  std::vector<ProcessExit> reap();
  /// SIGTERM to each module in reverse start order, SIGKILL after `grace`; returns their exits.
  std::vector<ProcessExit> stop_all(std::chrono::milliseconds grace);
  std::optional<pid_t> pid_of(const std::string& module) const;
  /// What it started and has not reaped yet, in start order.
  const std::vector<Child>& children() const { return children_; }
  const std::string& log_dir() const { return log_dir_; }
  std::string log_path(const std::string& module) const;

 private:
  ProcessExit finished(const Child& child, int status) const;

  std::string log_dir_;
  int death_signal_;
  std::vector<Child> children_;  // in start order
};

}  // namespace oscar
