#include "oscar/registry/supervisor.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar {
namespace {

using ::testing::HasSubstr;

std::vector<ProcessExit> reap_within(Supervisor& s, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  std::vector<ProcessExit> out;
  while (out.empty() && std::chrono::steady_clock::now() < until) {
    out = s.reap();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return out;
}

std::string dir(const std::string& name) {
  const auto d = ::testing::TempDir() + "/supervisor_" + name + std::to_string(getpid());
  std::filesystem::remove_all(d);
  return d;
}

TEST(Supervisor, ReportsTheExitCodeAndTheLastOutput) {
  Supervisor s(dir("exit"));
  s.start("m", 1, {"sh", "-c", "echo first; echo \"last $GREETING\"; exit 3"}, {"GREETING=hi"});
  const auto exits = reap_within(s, std::chrono::seconds(5));
  ASSERT_EQ(exits.size(), 1u);
  EXPECT_EQ(exits[0].exit_code, 3);
  EXPECT_EQ(exits[0].signal, 0);
  EXPECT_EQ(exits[0].describe(), "exited with code 3");
  EXPECT_THAT(exits[0].last_output, HasSubstr("last hi"));
  std::ifstream log(s.log_path("m"));
  std::stringstream text;
  text << log.rdbuf();
  EXPECT_THAT(text.str(), HasSubstr("=== m incarnation 1 started"));
}

// A module must not hold its monitor's sockets and shared-memory lock files (nor a monitor
// boot's): a killed monitor would look alive to every sweeper while its modules live.
TEST(Supervisor, AChildInheritsNoFileOfTheSupervisor) {
  const auto held = dir("held") + ".txt";
  const int fd = ::open(held.c_str(), O_WRONLY | O_CREAT, 0644);  // inheritable, as DDS's are
  ASSERT_GE(fd, 3);
  Supervisor s(dir("inherit"));
  s.start("m", 1,
          {"sh", "-c", fmt::format("test -e /proc/$$/fd/{} && echo inherited || echo none", fd)});
  const auto exits = reap_within(s, std::chrono::seconds(5));
  ::close(fd);
  std::filesystem::remove(held);
  ASSERT_EQ(exits.size(), 1u);
  EXPECT_THAT(exits[0].last_output, ::testing::EndsWith("\nnone"));
}

TEST(Supervisor, ReportsASignal) {
  Supervisor s(dir("signal"));
  s.start("m", 2, {"sleep", "30"});
  ASSERT_TRUE(s.signal("m", SIGKILL));
  const auto exits = reap_within(s, std::chrono::seconds(5));
  ASSERT_EQ(exits.size(), 1u);
  EXPECT_EQ(exits[0].signal, SIGKILL);
  EXPECT_EQ(exits[0].incarnation, 2u);
  EXPECT_THAT(exits[0].describe(), HasSubstr("killed by signal 9"));
}

TEST(Supervisor, AProgramThatCannotStartIsAClearError) {
  Supervisor s(dir("missing"));
  try {
    s.start("m", 1, {"/no/such/program"});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "cannot start m: /no/such/program: No such file or directory");
  }
  EXPECT_FALSE(s.pid_of("m"));
}

TEST(Supervisor, StopsInReverseStartOrderAndWakesStoppedProcesses) {
  Supervisor s(dir("order"));
  s.start("first", 1, {"sleep", "30"});
  s.start("second", 1, {"sleep", "30"});
  ASSERT_TRUE(s.signal("first", SIGSTOP));
  const auto exits = s.stop_all(std::chrono::milliseconds(2000));
  ASSERT_EQ(exits.size(), 2u);
  EXPECT_EQ(exits[0].module, "second");
  EXPECT_EQ(exits[1].module, "first");
  EXPECT_EQ(exits[1].signal, SIGTERM);
}

}  // namespace
}  // namespace oscar
