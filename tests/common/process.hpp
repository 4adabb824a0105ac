#pragma once
// A child process for integration tests: started with fork/exec, output to a log file, stopped
// (SIGTERM, then SIGKILL) when the object goes away, so a failed test leaves nothing behind.

#include <fcntl.h>
#include <linux/close_range.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "oscar/test_domain.hpp"

namespace oscar::test {

inline std::string build_dir() {
  const char* dir = std::getenv("OSCAR_BUILD_DIR");
  return dir ? dir : ".";
}

inline std::string bin(const std::string& program) { return build_dir() + "/bin/" + program; }

class Process {
 public:
  Process(std::vector<std::string> argv, std::string log) : log_(std::move(log)) {
    // Everything that allocates happens before fork: the test runs other threads (DDS's), and a
    // child that needs a lock one of them held when it forked (the allocator's under TSan) waits
    // forever. The child only redirects, lets go of the test's sockets and files, and execs.
    std::vector<char*> args;
    for (auto& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    const int fd = ::open(log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    pid_ = fork();
    if (pid_ == 0) {
      if (fd >= 0) {
        dup2(fd, 1);
        dup2(fd, 2);
      }
      close_range(3, ~0U, CLOSE_RANGE_CLOEXEC);
      execv(args[0], args.data());
      _exit(127);
    }
    if (fd >= 0) ::close(fd);
  }
  ~Process() { stop(); }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  pid_t pid() const { return pid_; }

  /// The exit code, once the process ended within `timeout`.
  std::optional<int> wait(std::chrono::milliseconds timeout) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (!status_) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        break;
      }
      if (std::chrono::steady_clock::now() > until) return std::nullopt;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return status_;
  }

  void stop() {
    if (pid_ <= 0 || status_) return;
    kill(pid_, SIGTERM);
    if (!wait(std::chrono::seconds(5))) {
      kill(pid_, SIGKILL);
      wait(std::chrono::seconds(5));
    }
  }

  std::string output() const {
    std::ifstream in(log_);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

 private:
  std::string log_;
  pid_t pid_ = -1;
  std::optional<int> status_;
};

/// A DDS domain of this test process's own, held for as long as the process lives: tests run
/// in parallel (ctest -j) never share one, and none of them takes a booted system's. It is the
/// first free one from a point of the pid down, so consecutive tests rarely reuse a domain where
/// a process of the one before may still be ending.
inline int test_domain() { return process_test_domain(1 + static_cast<int>(getpid() % 200)); }

/// "<temporary folder>/<name>_<pid>": a path of this test process's own.
inline std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / (name + "_" + std::to_string(getpid())))
      .string();
}

/// An oscar-run process named `module` on test_domain(), with further arguments (e.g. `-k
/// bench_source:fast -m continuous:10ms`); its output goes to temp_path(module + ".log").
inline std::unique_ptr<Process> run_module(const std::string& module,
                                           std::vector<std::string> args) {
  std::vector<std::string> argv{bin("oscar-run"), "--name", module, "--domain",
                                std::to_string(test_domain())};
  argv.insert(argv.end(), args.begin(), args.end());
  return std::make_unique<Process>(argv, temp_path(module + ".log"));
}

}  // namespace oscar::test
