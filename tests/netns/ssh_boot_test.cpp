// Boot over SSH for real (issue 19 item 1): test hosts in network namespaces, each with an
// OpenSSH server of its own; `oscar boot` runs on h1 and reaches the other hosts only through
// `ssh:` (no `ip netns exec`). A three-host system boots, cues cross the hosts, Ctrl-C shuts it
// down in order; boot refuses hosts that are not ready, naming host and cause, before it
// starts anything; a killed ssh connection stops that host's modules. Root and sshd only;
// skipped with a message otherwise.
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "proc.hpp"     // tests/common
#include "process.hpp"  // tests/common
#include "ssh_hosts.hpp"
#include "test_hosts.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using ::testing::HasSubstr;

std::string read(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

// Live processes whose command line holds every one of `parts` (separated by NULs there).
std::vector<pid_t> processes_with(const std::vector<std::string>& parts) {
  std::vector<pid_t> out;
  for (const long pid : test::listed_pids()) {
    const auto cmd = test::proc_file(pid, "cmdline");
    const auto stat = test::proc_file(pid, "stat");
    const auto close = stat.rfind(')');
    if (close == std::string::npos || close + 2 >= stat.size() || stat[close + 2] == 'Z') continue;
    bool all = !cmd.empty();
    for (const auto& p : parts) all = all && cmd.find(p) != std::string::npos;
    if (all) out.push_back(static_cast<pid_t>(pid));
  }
  return out;
}

// Their command lines, for a failure message.
std::string command_lines(const std::vector<pid_t>& pids) {
  std::string out;
  for (const auto pid : pids) {
    auto cmd = test::proc_file(pid, "cmdline");
    std::replace(cmd.begin(), cmd.end(), '\0', ' ');
    out += std::to_string(pid) + ": " + cmd + "\n";
  }
  return out;
}

bool eventually(const std::function<bool()>& done, std::chrono::seconds limit) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(100ms);
  }
  return true;
}

class SshBoot : public testing::Test {
 protected:
  void SetUp() override {
    if (const auto why = test::TestHosts::unavailable(); !why.empty()) GTEST_SKIP() << why;
    if (const auto why = test::SshHosts::unavailable(); !why.empty()) GTEST_SKIP() << why;
    folder_ = test::temp_path("ssh_boot");  // the system file's folder, for one host to miss
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_);
    file_ = folder_ + "/system.yaml";
    log_dir_ = test::temp_path("ssh_boot_logs");
    std::filesystem::remove_all(log_dir_);
  }
  void TearDown() override {
    boot_.reset();
    ssh_.reset();
    hosts_.reset();
    std::filesystem::remove_all(folder_);
    if (!HasFailure()) {  // kept to read after a failure
      std::filesystem::remove_all(log_dir_);
      std::filesystem::remove(test::temp_path("ssh_boot.log"));
    }
  }

  void make_hosts(int n) {
    hosts_ = std::make_unique<test::TestHosts>(n);
    ssh_ = std::make_unique<test::SshHosts>(*hosts_);
  }

  // src on h1 -> relay on h2 -> sink on h3; h2 and h3 reached over ssh.
  void write_three_host_system() {
    std::ofstream(file_) << fmt::format(R"(
system: over_ssh
lease: 1s
hosts:
  h1: {{ local: true, address: {} }}
  h2: {}
  h3: {}
modules:
  - name: src
    host: h1
    kernels: [ {{ type: bench_source, name: src, params: {{ type: LineSeg3DSeq, lines: 100 }} }} ]
    mode: {{ continuous: 20ms }}
  - name: relay
    host: h2
    kernels: [ {{ type: relay, name: relay, params: {{ type: LineSeg3DSeq }}, inputs: {{ in: src/out }} }} ]
    mode: single_step
    restart: {{ policy: manual }}
  - name: sink
    host: h3
    kernels: [ {{ type: bench_sink, name: sink, params: {{ type: LineSeg3DSeq, log_every: 1s }}, inputs: {{ in: relay/out }} }} ]
    mode: single_step
)",
                                        hosts_->address(1), ssh_->entry(2), ssh_->entry(3));
  }

  void boot(std::vector<std::string> extra = {}) {
    auto argv = hosts_->on(1);  // boot and the registry run on h1, the rest only over ssh
    argv.insert(argv.end(),
                {test::bin("oscar-boot"), file_, "--domain", std::to_string(test::test_domain()),
                 "--log-dir", log_dir_, "--timeout", "60"});
    argv.insert(argv.end(), extra.begin(), extra.end());
    boot_ = std::make_unique<test::Process>(argv, test::temp_path("ssh_boot.log"));
  }

  bool boot_says(const std::string& text, std::chrono::seconds limit) {
    return eventually([&] { return boot_->output().find(text) != std::string::npos; }, limit);
  }

  // The module process `module` (oscar-run ... --module M), wherever it runs.
  std::vector<pid_t> module_processes(const std::string& module) {
    return processes_with({"oscar-run", file_, std::string("--module") + '\0' + module + '\0'});
  }

  std::string folder_, file_, log_dir_;
  std::unique_ptr<test::TestHosts> hosts_;
  std::unique_ptr<test::SshHosts> ssh_;
  std::unique_ptr<test::Process> boot_;
};

TEST_F(SshBoot, ThreeHostsCuesCrossThemAndCtrlCStopsEveryHostInOrder) {
  make_hosts(3);
  ssh_->serve(2);
  ssh_->serve(3);
  write_three_host_system();
  boot();
  ASSERT_TRUE(boot_says("running after", 90s)) << boot_->output();
  // No `ip netns exec` to h2 or h3: their monitors are the remote commands of ssh sessions.
  EXPECT_TRUE(processes_with({"netns", "oscar-monitor", "h2"}).empty());
  ASSERT_EQ(processes_with({"ssh", "root@" + hosts_->address(2), "oscar-monitor"}).size(), 1u);
  ASSERT_EQ(module_processes("relay").size(), 1u);
  ASSERT_EQ(module_processes("sink").size(), 1u);
  // Cues cross h1 -> h2 -> h3: the sink on h3 counts what reached it through the relay (its
  // summary comes to boot's merged log).
  const std::regex counted(R"(\[sink\] LineSeg3DSeq: ([1-9][0-9]*) cues)");
  EXPECT_TRUE(eventually([&] { return std::regex_search(boot_->output(), counted); }, 30s))
      << boot_->output();

  kill(boot_->pid(), SIGINT);
  ASSERT_EQ(boot_->wait(60s), 0) << boot_->output();
  const auto out = boot_->output();
  EXPECT_THAT(out, HasSubstr("all processes stopped"));
  EXPECT_THAT(out, ::testing::Not(HasSubstr(" error "))) << "an orderly shutdown is no error";
  // The registry stopped the modules one by one in reverse file order, each by its host's
  // monitor (SIGTERM, exit code 0): sink on h3, then relay on h2, then src on h1.
  const auto ended = [&](const std::string& host, const std::string& module) {
    // An ssh host's monitor keeps its own log there; h1's is the one boot keeps.
    const auto log =
        read(log_dir_ + (host == "h1" ? "/monitor-h1.log" : "/" + host + "/oscar-monitor.log"));
    std::smatch m;
    const std::regex line("([0-9:.]{12}) .*" + module + R"( \(pid [0-9]+\) exited with code 0)");
    EXPECT_TRUE(std::regex_search(log, m, line)) << host << ":\n" << log;
    return m.empty() ? std::string() : m[1].str();
  };
  const auto sink_end = ended("h3", "sink");
  const auto relay_end = ended("h2", "relay");
  const auto src_end = ended("h1", "src");
  EXPECT_LE(sink_end, relay_end);
  EXPECT_LE(relay_end, src_end);
  // Each remote monitor ended too: told by the registry, or when boot closed its connection (the
  // registry's last message does not always reach it before the registry exits). Its own log on
  // its host says so either way.
  for (const std::string host : {"h2", "h3"}) {
    const auto log = log_dir_ + "/" + host + "/oscar-monitor.log";
    EXPECT_TRUE(eventually([&] { return read(log).find("] stopped") != std::string::npos; }, 10s))
        << read(log);
  }
  // A monitor whose connection boot cut at the end finishes stopping on its own, after boot.
  EXPECT_TRUE(eventually([&] { return processes_with({file_}).empty(); }, 10s))
      << "a process of the system is left:\n"
      << command_lines(processes_with({file_}));
}

TEST_F(SshBoot, RefusesHostsThatAreNotReadyNamingHostAndCauseBeforeStartingAnything) {
  make_hosts(10);
  const auto build = std::filesystem::canonical(test::build_dir()).string();
  const auto bin = build + "/bin";
  const auto plugins = build + "/lib/oscar/plugins";
  ssh_->serve(2);  // ready
  // h3: no sshd at all.
  ssh_->serve(4);  // h4 is offered a key it does not accept
  ssh_->serve(5, ssh_->mount_command(bin, {},
                                     {{"oscar-monitor",
                                       "#!/bin/sh\necho "
                                       "'oscar-monitor 0.0.9'\n"}}));
  ssh_->serve(6, ssh_->mount_command(bin, {"oscar-monitor"}));
  ssh_->serve(7, ssh_->mount_command(plugins, {"liboscar_kernel_relay.so"}));
  ssh_->serve(8, ssh_->mount_command(folder_, {"system.yaml"}));
  ssh_->serve(9);  // h9's host key is not in the known hosts boot is given
  ssh_->serve(10, ssh_->mount_command(folder_, {}, {{"system.yaml", "system: another\n"}}));
  std::string hosts = fmt::format("  h1: {{ local: true, address: {} }}\n", hosts_->address(1));
  for (int i = 2; i <= 10; ++i) {
    hosts += fmt::format("  h{}: {}\n", i,
                         ssh_->entry(i, i == 4 ? "stranger_key" : "client_key",
                                     i == 9 ? "no_known_hosts" : "known_hosts"));
  }
  // A relative path, resolved beside the system file on every host that has it.
  std::filesystem::create_directories(folder_ + "/my_plugins");
  std::ofstream(file_) << fmt::format(R"(
system: not_ready
lease: 1s
plugins: [my_plugins]
hosts:
{}modules:
  - name: src
    host: h1
    kernels: [ {{ type: bench_source, name: src, params: {{ type: Bool }} }} ]
    mode: {{ continuous: 20ms }}
  - name: relay
    host: h7
    kernels: [ {{ type: relay, name: relay, params: {{ type: Bool }}, inputs: {{ in: src/out }} }} ]
    mode: single_step
)",
                                      hosts);
  boot();
  ASSERT_EQ(boot_->wait(90s), 2) << boot_->output();
  const auto out = boot_->output();
  const auto at = [&](int i) {
    return fmt::format("host 'h{}' (root@{}): ", i, hosts_->address(i));
  };
  EXPECT_THAT(out, HasSubstr("8 ssh hosts are not ready, nothing started"));
  EXPECT_THAT(out, ::testing::Not(HasSubstr("host 'h2'")));
  EXPECT_THAT(out, HasSubstr(at(3) + "unreachable (ssh: connect to host " + hosts_->address(3) +
                             " port 2222: Connection refused)"));
  EXPECT_THAT(out, HasSubstr(at(4) + "authentication refused (root@" + hosts_->address(4) +
                             ": Permission denied (publickey).)"));
  EXPECT_THAT(out,
              HasSubstr(at(5) + "version mismatch: oscar-monitor 0.0.9 there, oscar-monitor "));
  EXPECT_THAT(out, HasSubstr(at(6) + "missing program " + bin + "/oscar-monitor"));
  EXPECT_THAT(out, HasSubstr(at(7) + "module 'relay': "));
  EXPECT_THAT(out, ::testing::ContainsRegex("h7.*liboscar_kernel_relay|h7.*'relay'"));
  EXPECT_THAT(out, HasSubstr(at(8) + "the system file " + file_ + " is not there"));
  EXPECT_THAT(out,
              HasSubstr(at(9) + "its host key is not trusted (Host key verification failed.)"));
  EXPECT_THAT(out, HasSubstr(at(10) + "the system file " + file_ + " differs from boot's"));
  // Nothing started: no registry, no monitor, no log folder.
  EXPECT_FALSE(std::filesystem::exists(log_dir_));
  EXPECT_TRUE(processes_with({file_}).empty());
}

TEST_F(SshBoot, AnSshHostWithoutAddressIsRefused) {
  make_hosts(2);
  std::ofstream(file_) << "hosts: { h1: { local: true }, h2: { ssh: root@h2 } }\n"
                          "modules: [ { name: a, host: h1, kernels: [ { type: relay, params: { "
                          "type: Bool } } ] } ]\n";
  boot({"--check"});
  ASSERT_EQ(boot_->wait(30s), 2) << boot_->output();
  EXPECT_THAT(boot_->output(), HasSubstr("hosts.h2: an ssh host needs address:"));
}

TEST_F(SshBoot, AKilledSshConnectionStopsThatHostsModules) {
  make_hosts(3);
  ssh_->serve(2);
  ssh_->serve(3);
  write_three_host_system();
  boot();
  ASSERT_TRUE(boot_says("running after", 90s)) << boot_->output();
  const auto relay = module_processes("relay");
  ASSERT_EQ(relay.size(), 1u);
  const auto link = processes_with({"ssh", "root@" + hosts_->address(2), "oscar-monitor"});
  ASSERT_EQ(link.size(), 1u);
  const auto remote_monitor =
      processes_with({"oscar-monitor", "--over-ssh", std::string("--host") + '\0' + "h2" + '\0'});
  ASSERT_EQ(remote_monitor.size(), 1u);

  ASSERT_EQ(kill(link[0], SIGKILL), 0);  // the connection dies; h2's processes are not touched
  EXPECT_TRUE(eventually([&] { return kill(relay[0], 0) != 0; }, 20s)) << "relay still runs";
  EXPECT_TRUE(eventually([&] { return kill(remote_monitor[0], 0) != 0; }, 20s))
      << "h2's monitor still runs";
  // In order: the monitor stopped the relay (SIGTERM, exit code 0); it did not die with it. The
  // monitor's last words stay on its host.
  const auto monitor_log = read(log_dir_ + "/h2/oscar-monitor.log");
  EXPECT_THAT(monitor_log, HasSubstr("the ssh connection to boot is gone: stopping this host's "
                                     "modules"));
  EXPECT_THAT(monitor_log, ::testing::ContainsRegex(R"(relay \(pid [0-9]+\) exited with code 0)"))
      << monitor_log;
  EXPECT_THAT(monitor_log, HasSubstr("] stopped")) << monitor_log;
  // The rest of the system learns that the relay is gone; h3 goes on.
  EXPECT_TRUE(boot_says("'relay' ", 20s)) << boot_->output();
  EXPECT_EQ(module_processes("sink").size(), 1u);
  kill(boot_->pid(), SIGINT);
  EXPECT_TRUE(boot_->wait(60s)) << boot_->output();
  // A monitor whose connection boot cut at the end finishes stopping on its own, after boot.
  EXPECT_TRUE(eventually([&] { return processes_with({file_}).empty(); }, 10s))
      << "a process of the system is left:\n"
      << command_lines(processes_with({file_}));
}

// With --copy-system-file boot puts its system file on each ssh host first: on h2 it is missing,
// on h3 an old one differs (each sees its own file system); both then boot.
TEST_F(SshBoot, CopiesTheSystemFileAlongWhenAsked) {
  make_hosts(3);
  ssh_->serve(2, ssh_->mount_command(folder_, {"system.yaml"}));
  ssh_->serve(3, ssh_->mount_command(folder_, {}, {{"system.yaml", "system: old\n"}}));
  write_three_host_system();
  boot({"--copy-system-file"});
  ASSERT_TRUE(boot_says("running after", 90s)) << boot_->output();
  const std::regex counted(R"(\[sink\] LineSeg3DSeq: ([1-9][0-9]*) cues)");
  EXPECT_TRUE(eventually([&] { return std::regex_search(boot_->output(), counted); }, 30s))
      << boot_->output();
  kill(boot_->pid(), SIGINT);
  EXPECT_EQ(boot_->wait(60s), 0) << boot_->output();
}

// A boot killed with SIGKILL takes its ssh clients with it (PR_SET_PDEATHSIG): each remote
// monitor sees its connection end and stops its host's modules in order.
TEST_F(SshBoot, AKilledBootStopsTheModulesOfItsSshHostsInOrder) {
  make_hosts(3);
  ssh_->serve(2);
  ssh_->serve(3);
  write_three_host_system();
  boot();
  ASSERT_TRUE(boot_says("running after", 90s)) << boot_->output();
  const auto relay = module_processes("relay");
  const auto sink = module_processes("sink");
  ASSERT_EQ(relay.size(), 1u);
  ASSERT_EQ(sink.size(), 1u);
  ASSERT_EQ(kill(boot_->pid(), SIGKILL), 0);
  EXPECT_TRUE(eventually([&] { return kill(relay[0], 0) != 0 && kill(sink[0], 0) != 0; }, 20s))
      << "a module of an ssh host still runs";
  for (const std::string module : {"relay", "sink"}) {
    const auto log = log_dir_ + (module == "relay" ? "/h2" : "/h3") + "/oscar-monitor.log";
    EXPECT_TRUE(eventually([&] { return read(log).find("] stopped") != std::string::npos; }, 10s))
        << read(log);
    EXPECT_THAT(read(log), HasSubstr("the ssh connection to boot is gone"));
    EXPECT_THAT(read(log),
                ::testing::ContainsRegex(module + R"( \(pid [0-9]+\) exited with code 0)"));
  }
  EXPECT_TRUE(eventually([&] { return processes_with({file_}).empty(); }, 20s))
      << "a process of the system is left:\n"
      << command_lines(processes_with({file_}));
}

}  // namespace
}  // namespace oscar
