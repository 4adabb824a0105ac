#include "oscar/registry/run_command.hpp"

#include <fcntl.h>
#include <linux/close_range.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

namespace oscar {
namespace {

void pipe_or_throw(int (&ends)[2]) {
  if (pipe2(ends, O_CLOEXEC) != 0) {
    throw std::runtime_error(fmt::format("pipe: {}", std::strerror(errno)));
  }
}

// write() that returns EPIPE instead of killing the process when the reader is gone: SIGPIPE is
// blocked in this thread for the call and taken back if it was raised.
ssize_t write_no_sigpipe(int fd, const char* data, std::size_t size) {
  sigset_t pipe_signal;
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  sigset_t before;
  pthread_sigmask(SIG_BLOCK, &pipe_signal, &before);
  const auto put = ::write(fd, data, size);
  if (put < 0 && errno == EPIPE) {
    const timespec now{};
    sigtimedwait(&pipe_signal, nullptr, &now);
    errno = EPIPE;
  }
  pthread_sigmask(SIG_SETMASK, &before, nullptr);
  return put;
}

}  // namespace

CommandResult run_command(const std::vector<std::string>& argv, std::chrono::milliseconds timeout,
                          const std::string& input) {
  if (argv.empty()) throw std::runtime_error("run_command: empty command");
  int out[2];
  int in[2];
  pipe_or_throw(out);
  pipe_or_throw(in);
  std::vector<std::string> args = argv;
  std::vector<char*> cargs;
  for (auto& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    // Only async-signal-safe calls from here: the caller may run other threads.
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    setpgid(0, 0);
    dup2(in[0], 0);
    dup2(out[1], 1);
    dup2(out[1], 2);
    close_range(3, ~0U, CLOSE_RANGE_CLOEXEC);  // the caller's sockets and files stay with it
    execvp(cargs[0], cargs.data());
    constexpr char kFailed[] = ": cannot be started\n";
    (void)!::write(2, cargs[0], std::strlen(cargs[0]));
    (void)!::write(2, kFailed, sizeof kFailed - 1);
    _exit(127);
  }
  ::close(out[1]);
  ::close(in[0]);
  if (pid < 0) {
    ::close(out[0]);
    ::close(in[1]);
    throw std::runtime_error(fmt::format("fork: {}", std::strerror(errno)));
  }
  fcntl(in[1], F_SETFL, O_NONBLOCK);
  std::size_t written = 0;
  if (input.empty()) {
    ::close(in[1]);
    in[1] = -1;
  }
  CommandResult result;
  const auto until = std::chrono::steady_clock::now() + timeout;
  bool timed_out = false;
  char buffer[4096];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        until - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    // Writes and reads interleaved: a child that answers before it has read all its input
    // must not block us, nor we it.
    pollfd p[2] = {{out[0], POLLIN, 0}, {in[1], POLLOUT, 0}};
    if (poll(p, in[1] >= 0 ? 2 : 1, static_cast<int>(left.count())) <= 0) continue;
    if (in[1] >= 0 && (p[1].revents & (POLLOUT | POLLERR | POLLHUP)) != 0) {
      const auto put = write_no_sigpipe(in[1], input.data() + written, input.size() - written);
      if (put > 0) written += static_cast<std::size_t>(put);
      if (put < 0 && errno != EAGAIN) written = input.size();  // the child closed its stdin
      if (written == input.size()) {
        ::close(in[1]);
        in[1] = -1;
      }
    }
    if ((p[0].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
    const auto got = ::read(out[0], buffer, sizeof buffer);
    if (got <= 0) break;
    result.output.append(buffer, static_cast<std::size_t>(got));
  }
  ::close(out[0]);
  if (in[1] >= 0) ::close(in[1]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  result.exit_code = !timed_out && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace oscar
