#pragma once
// The CPU a process has used so far, as the benchmarks report it (user + system time from
// /proc/<pid>/stat; 0 for a process that is gone), and the CPU the whole machine has used.

#include <unistd.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "proc.hpp"

namespace oscar::test {

namespace internal {
// User + system time from a /proc/<pid>/stat text, in seconds; 0 if there is none.
inline double stat_cpu_seconds(const std::string& stat) {
  const auto after_name = stat.rfind(')');  // the name may hold spaces and parentheses
  if (after_name == std::string::npos) return 0;
  std::istringstream fields(stat.substr(after_name + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}
}  // namespace internal

inline double cpu_seconds(long pid) { return internal::stat_cpu_seconds(proc_file(pid, "stat")); }

/// What a program costs the machine, summed over its processes running now (their own time, not
/// that of children they waited for: a daemon's would hold every earlier session's).
struct ProgramCpu {
  double seconds = 0;  ///< user + system
  int processes = 0;
};

/// The CPU of every process running now whose name (its `comm`) `counts`, by name.
template <class Predicate>
std::map<std::string, ProgramCpu> cpu_by_program(Predicate counts) {
  std::map<std::string, ProgramCpu> by_name;
  for (const long pid : listed_pids()) {
    const auto stat = proc_file(pid, "stat");
    const auto open = stat.find('('), close = stat.rfind(')');
    if (open == std::string::npos || close == std::string::npos || close < open) continue;
    const auto name = stat.substr(open + 1, close - open - 1);
    if (!counts(name)) continue;
    auto& program = by_name[name];
    program.seconds += internal::stat_cpu_seconds(stat);
    ++program.processes;
  }
  return by_name;
}

/// CPU-seconds every core of the machine has spent busy since it started (/proc/stat: user,
/// nice, system, irq, softirq and steal time), whoever used them.
inline double machine_busy_cpu_seconds() {
  std::ifstream stat("/proc/stat");
  std::string cpu;
  unsigned long long user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0,
                     steal = 0;
  stat >> cpu >> user >> nice >> system >> idle >> iowait >> irq >> softirq >> steal;
  return static_cast<double>(user + nice + system + irq + softirq + steal) /
         static_cast<double>(sysconf(_SC_CLK_TCK));
}

}  // namespace oscar::test
