#pragma once
// The CPU a process has used so far, as the benchmarks report it (user + system time from
// /proc/<pid>/stat; 0 for a process that is gone), and the CPU the whole machine has used.

#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

#include "proc.hpp"

namespace oscar::test {

inline double cpu_seconds(long pid) {
  const auto stat = proc_file(pid, "stat");
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
