#include "oscar/registry/supervisor.hpp"

#include <fcntl.h>
#include <linux/close_range.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <ctime>
#include <deque>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

namespace oscar {
namespace {

std::string last_lines(const std::string& path, std::size_t n) {
  std::ifstream in(path);
  std::deque<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    lines.push_back(line);
    if (lines.size() > n) lines.pop_front();
  }
  std::string out;
  for (const auto& l : lines) out += (out.empty() ? "" : "\n") + l;
  return out;
}

}  // namespace

std::string ProcessExit::describe() const {
  if (signal != 0) return fmt::format("killed by signal {} ({})", signal, strsignal(signal));
  return fmt::format("exited with code {}", exit_code);
}

Supervisor::Supervisor(std::string log_dir, int death_signal)
    : log_dir_(std::move(log_dir)), death_signal_(death_signal) {
  std::error_code ec;
  std::filesystem::create_directories(log_dir_, ec);
  if (ec) {
    throw std::runtime_error(
        fmt::format("cannot create the log directory {}: {}", log_dir_, ec.message()));
  }
}

Supervisor::~Supervisor() { stop_all(std::chrono::milliseconds(2000)); }

std::string Supervisor::log_path(const std::string& module) const {
  return log_dir_ + "/" + module + ".log";
}

pid_t Supervisor::start(const std::string& module, unsigned incarnation,
                        const std::vector<std::string>& argv, const std::vector<std::string>& env) {
  if (argv.empty()) throw std::invalid_argument("cannot start " + module + ": empty command");
  const auto log = log_path(module);
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw std::runtime_error(
        fmt::format("cannot start {}: log {}: {}", module, log, std::strerror(errno)));
  }
  const auto header = fmt::format("=== {} incarnation {} started at {} ===\n", module, incarnation,
                                  std::time(nullptr));
  (void)!::write(fd, header.data(), header.size());
  int report[2];  // the child writes errno here if exec fails; closed on exec otherwise
  if (pipe2(report, O_CLOEXEC) != 0) {
    ::close(fd);
    throw std::runtime_error(
        fmt::format("cannot start {}: pipe: {}", module, std::strerror(errno)));
  }
  std::vector<std::string> args = argv;
  std::vector<char*> cargs;
  for (auto& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  // The environment is built before fork: after it, only async-signal-safe calls.
  std::vector<std::string> envs = env;
  for (char** e = environ; *e; ++e) {
    const std::string entry = *e;
    const auto name = entry.substr(0, entry.find('=') + 1);
    const bool overridden = std::any_of(env.begin(), env.end(),
                                        [&](const std::string& x) { return x.starts_with(name); });
    if (!overridden) envs.push_back(entry);
  }
  std::vector<char*> cenv;
  for (auto& e : envs) cenv.push_back(e.data());
  cenv.push_back(nullptr);
  const pid_t parent = getpid();
  const int death_signal = death_signal_;
  const pid_t pid = fork();
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, death_signal);
    if (getppid() != parent) _exit(127);  // the supervisor died before prctl
    setpgid(0, 0);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    dup2(fd, 1);
    dup2(fd, 2);
    const int devnull = ::open("/dev/null", O_RDONLY);
    if (devnull >= 0) dup2(devnull, 0);
    // Nothing else of the supervisor's goes along: its DDS sockets, and the lock files of its
    // shared-memory segments, which would make it look alive to every sweeper for as long as
    // the child lives (the report pipe is close-on-exec already).
    close_range(3, ~0U, CLOSE_RANGE_CLOEXEC);
    execvpe(cargs[0], cargs.data(), cenv.data());
    const int err = errno;
    (void)!::write(report[1], &err, sizeof err);
    _exit(127);
  }
  ::close(report[1]);
  ::close(fd);
  if (pid < 0) {
    ::close(report[0]);
    throw std::runtime_error(
        fmt::format("cannot start {}: fork: {}", module, std::strerror(errno)));
  }
  int err = 0;
  const auto got = ::read(report[0], &err, sizeof err);
  ::close(report[0]);
  if (got == sizeof err) {
    waitpid(pid, nullptr, 0);
    throw std::runtime_error(
        fmt::format("cannot start {}: {}: {}", module, argv.front(), std::strerror(err)));
  }
  children_.push_back(Child{module, incarnation, pid});
  return pid;
}

bool Supervisor::signal(const std::string& module, int sig) {
  const auto pid = pid_of(module);
  return pid && ::kill(*pid, sig) == 0;
}

std::optional<pid_t> Supervisor::pid_of(const std::string& module) const {
  for (const auto& c : children_) {
    if (c.module == module) return c.pid;
  }
  return std::nullopt;
}

ProcessExit Supervisor::finished(const Child& child, int status) const {
  ProcessExit e;
  e.module = child.module;
  e.incarnation = child.incarnation;
  e.pid = child.pid;
  if (WIFSIGNALED(status)) {
    e.signal = WTERMSIG(status);
  } else {
    e.exit_code = WEXITSTATUS(status);
  }
  e.last_output = last_lines(log_path(child.module), 5);
  return e;
}

std::vector<ProcessExit> Supervisor::reap() {
  std::vector<ProcessExit> out;
  for (auto it = children_.begin(); it != children_.end();) {
    int status = 0;
    if (waitpid(it->pid, &status, WNOHANG) == it->pid) {
      out.push_back(finished(*it, status));
      it = children_.erase(it);
    } else {
      ++it;
    }
  }
  return out;
}

std::vector<ProcessExit> Supervisor::stop_all(std::chrono::milliseconds grace) {
  std::vector<ProcessExit> out;
  while (!children_.empty()) {
    const Child child = children_.back();
    children_.pop_back();
    ::kill(child.pid, SIGTERM);
    ::kill(child.pid, SIGCONT);  // a stopped process cannot act on SIGTERM
    const auto until = std::chrono::steady_clock::now() + grace;
    int status = 0;
    while (waitpid(child.pid, &status, WNOHANG) != child.pid) {
      if (std::chrono::steady_clock::now() > until) {
        ::kill(child.pid, SIGKILL);
        waitpid(child.pid, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    out.push_back(finished(child, status));
  }
  return out;
}

}  // namespace oscar
