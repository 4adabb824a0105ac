#pragma once
// OpenSSH servers on test hosts (issue 19 item 1): one sshd inside each chosen host's network
// namespace, listening only on that host's test address, port 2222, with a host key and an
// authorized client key the test makes in a temporary folder (nothing secret is committed). Key
// authentication only, no PAM; StrictModes off because the keys live in /tmp.
//
// Each sshd runs in the mount namespace `ip netns exec` gives it, so a test may change what that
// host sees of the file system (mount_command()) without touching the machine's: a host where a
// plugin, a program or the system file is missing, as on a computer set up differently.
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "process.hpp"  // tests/common
#include "test_hosts.hpp"

namespace oscar::test {

class SshHosts {
 public:
  static constexpr int kPort = 2222;

  /// Why sshd cannot run here (not installed), or "".
  static std::string unavailable() {
    if (!std::filesystem::exists("/usr/sbin/sshd") || !std::filesystem::exists("/usr/bin/ssh")) {
      return "needs OpenSSH (apt-get install openssh-server openssh-client)";
    }
    return "";
  }

  /// Keys for all servers, in a fresh folder; no server runs yet.
  explicit SshHosts(const TestHosts& hosts) : hosts_(hosts), dir_(temp_path("ssh_hosts")) {
    remove_folder();
    std::filesystem::create_directories(dir_);
    std::filesystem::create_directories("/run/sshd");  // sshd's privilege separation folder
    keygen(dir_ + "/host_key");
    keygen(dir_ + "/client_key");
    keygen(dir_ + "/stranger_key");  // a key no server accepts
    std::filesystem::copy_file(dir_ + "/client_key.pub", dir_ + "/authorized_keys");
    std::ofstream(dir_ + "/no_known_hosts").flush();
  }
  ~SshHosts() {
    servers_.clear();
    remove_folder();
  }
  SshHosts(const SshHosts&) = delete;
  SshHosts& operator=(const SshHosts&) = delete;

  /// Starts sshd on host i after running `prepare` (shell commands, e.g. mounts) in its mount
  /// namespace; returns once it listens.
  void serve(int i, const std::string& prepare = "") {
    const auto config = fmt::format("{}/sshd_config_{}", dir_, i);
    std::ofstream(config) << fmt::format(
        "ListenAddress {}:{}\nHostKey {}/host_key\nAuthorizedKeysFile {}/authorized_keys\n"
        "PidFile none\nUsePAM no\nStrictModes no\nPasswordAuthentication no\n"
        "KbdInteractiveAuthentication no\nPubkeyAuthentication yes\n"
        "PermitRootLogin prohibit-password\nClientAliveInterval 1\nClientAliveCountMax 3\n",
        hosts_.address(i), kPort, dir_, dir_);
    {
      std::ofstream known(dir_ + "/known_hosts", std::ios::app);
      known << fmt::format("[{}]:{} {}", hosts_.address(i), kPort, read(dir_ + "/host_key.pub"));
    }
    auto argv = hosts_.on(i);
    argv.insert(argv.end(),
                {"/bin/sh", "-c", prepare + "\nexec /usr/sbin/sshd -D -e -f " + config});
    const auto log = fmt::format("{}/sshd_{}.log", dir_, i);
    servers_[i] = std::make_unique<Process>(argv, log);
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (servers_[i]->output().find("Server listening") == std::string::npos) {
      if (std::chrono::steady_clock::now() > until ||
          servers_[i]->wait(std::chrono::milliseconds(0))) {
        throw std::runtime_error("sshd on test host " + std::to_string(i) + " did not start:\n" +
                                 servers_[i]->output());
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  /// The system file's entry for host i: `ssh:` root at its address, with the test's key and
  /// known hosts in `ssh_options` (`key` "stranger_key" offers a key the server refuses,
  /// `known_hosts` "no_known_hosts" trusts no host key).
  std::string entry(int i, const std::string& key = "client_key",
                    const std::string& known_hosts = "known_hosts") const {
    return fmt::format(
        "{{ ssh: root@{}, address: {}, ssh_options: [Port={}, IdentityFile={}/{}, "
        "IdentitiesOnly=yes, UserKnownHostsFile={}/{}, StrictHostKeyChecking=yes] }}",
        hosts_.address(i), hosts_.address(i), kPort, dir_, key, dir_, known_hosts);
  }

  /// Shell commands that make host i see `dir` with the entries `hidden` left out and the files
  /// `replaced` (name -> content, made executable) put in: a tmpfs over `dir` holding symbolic
  /// links to the other entries, reached through a bind mount of the original.
  std::string mount_command(const std::string& dir, const std::vector<std::string>& hidden,
                            const std::map<std::string, std::string>& replaced = {}) {
    const auto original = fmt::format("{}/original_{}", dir_, ++mounts_);
    std::filesystem::create_directories(original);
    std::string cmd = fmt::format("mount --bind {} {} && mount -t tmpfs tmpfs {} || exit 1\n", dir,
                                  original, dir);
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      const auto name = e.path().filename().string();
      if (std::find(hidden.begin(), hidden.end(), name) != hidden.end() || replaced.contains(name))
        continue;
      cmd += fmt::format("ln -s {}/{} {}/{}\n", original, name, dir, name);
    }
    for (const auto& [name, content] : replaced) {
      const auto file = fmt::format("{}/replacement_{}_{}", dir_, mounts_, name);
      std::ofstream(file) << content;
      std::filesystem::permissions(file, std::filesystem::perms::owner_all);
      cmd += fmt::format("cp {} {}/{}\n", file, dir, name);
    }
    return cmd;
  }

  /// sshd's log of host i (what it refused and why).
  std::string server_log(int i) const {
    const auto it = servers_.find(i);
    return it == servers_.end() ? std::string() : it->second->output();
  }

 private:
  // Never recursively: a mount point of an original folder (build/bin, ...) may still hold it
  // where an sshd's session lingers, and removing through it would delete the original.
  void remove_folder() const {
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir_, ec)) {
      std::filesystem::remove(e.path(), ec);
    }
    std::filesystem::remove(dir_, ec);
  }

  static void keygen(const std::string& path) {
    const auto cmd = fmt::format("ssh-keygen -q -t ed25519 -N '' -C oscar-test -f {}", path);
    if (std::system(cmd.c_str()) != 0) throw std::runtime_error("failed: " + cmd);
  }
  static std::string read(const std::string& path) {
    std::ifstream in(path);
    return std::string((std::istreambuf_iterator<char>(in)), {});
  }

  const TestHosts& hosts_;
  std::string dir_;
  std::map<int, std::unique_ptr<Process>> servers_;
  int mounts_ = 0;
};

}  // namespace oscar::test
