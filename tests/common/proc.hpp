#pragma once
// Reading other processes' /proc files in tests. A process may end between a listing of /proc
// and the read of one of its files; the read then fails (ESRCH), and read through an
// istreambuf_iterator that failure is an exception (std::ios_base::failure), which failed a
// test now and then. These read it as ended instead.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace oscar::test {

/// The contents of /proc/<pid>/<file> (e.g. "cmdline", "stat"), or "" if the process has ended.
inline std::string proc_file(long pid, const char* file) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/" + file);
  std::ostringstream contents;
  contents << in.rdbuf();  // a failed read ends the copy (failbit), it throws nothing
  return contents.str();
}

/// The pids /proc lists now.
inline std::vector<long> listed_pids() {
  std::vector<long> pids;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const auto name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") == std::string::npos) pids.push_back(std::stol(name));
  }
  return pids;
}

/// Whether every thread of process `pid` has stopped (state 'T', e.g. after SIGSTOP). kill()
/// returns before the signal took effect: a thread that was running may go on for a moment.
inline bool stopped(long pid) {
  std::error_code error;
  const auto tasks = "/proc/" + std::to_string(pid) + "/task";
  bool any = false;
  for (std::filesystem::directory_iterator task(tasks, error), end; !error && task != end;
       task.increment(error)) {  // a process that ends meanwhile is an error, not an exception
    const auto stat =
        proc_file(pid, ("task/" + task->path().filename().string() + "/stat").c_str());
    const auto state = stat.rfind(") ");
    if (state == std::string::npos || state + 2 >= stat.size() || stat[state + 2] != 'T')
      return false;
    any = true;
  }
  return any && !error;
}

}  // namespace oscar::test
