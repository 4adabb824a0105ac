#pragma once
// Test hosts on one machine (issue 3 item 5): network namespaces joined by veth pairs to a
// bridge in a namespace of its own, on a /24 of the 10.77/16 test range that this test owns.
// Everything is removed afterwards, also after a failed test, and stale leftovers of an earlier
// run with the same names are removed first. Nothing is connected to the machine's own network.

#include <unistd.h>

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace oscar::test {

class TestHosts {
 public:
  /// Why test hosts cannot be made here (not root, no `ip netns`), or "" if they can.
  static std::string unavailable() {
    if (geteuid() != 0) return "needs root to create network namespaces";
    const auto probe = fmt::format("oscar_probe_{}", getpid());
    if (std::system(
            fmt::format("ip netns add {} 2>/dev/null && ip netns del {}", probe, probe).c_str()) !=
        0) {
      return "`ip netns add` failed (no network namespaces in this sandbox)";
    }
    return "";
  }

  /// Hosts h1..hN with addresses 10.77.<subnet>.1..N.
  explicit TestHosts(int n) : tag_(fmt::format("o{}", getpid() % 100000)), subnet_(getpid() % 250) {
    cleanup();
    run("ip netns add {}", bridge_ns());
    run("ip -n {} link add br0 type bridge", bridge_ns());
    run("ip -n {} link set br0 up", bridge_ns());
    for (int i = 1; i <= n; ++i) {
      const auto ns = netns(i);
      run("ip netns add {}", ns);
      run("ip -n {} link set lo up", ns);
      run("ip link add {}h{} netns {} type veth peer name {}b{} netns {}", tag_, i, ns, tag_, i,
          bridge_ns());
      run("ip -n {} link set {}b{} master br0 up", bridge_ns(), tag_, i);
      run("ip -n {} addr add {}/24 dev {}h{}", ns, address(i), tag_, i);
      run("ip -n {} link set {}h{} up", ns, tag_, i);
      hosts_.push_back(ns);
    }
  }
  ~TestHosts() { cleanup(); }
  TestHosts(const TestHosts&) = delete;
  TestHosts& operator=(const TestHosts&) = delete;

  std::string netns(int i) const { return fmt::format("{}_h{}", tag_, i); }
  std::string address(int i) const { return fmt::format("10.77.{}.{}", subnet_, i); }
  /// Cuts host i off the others (its port on the bridge goes down), as a pulled cable would.
  void cut(int i) const { run("ip -n {} link set {}b{} down", bridge_ns(), tag_, i); }
  /// Connects host i again.
  void heal(int i) const { run("ip -n {} link set {}b{} up", bridge_ns(), tag_, i); }
  /// argv prefix that runs a program on host i.
  std::vector<std::string> on(int i) const {
    return {"/usr/bin/env", "ip", "netns", "exec", netns(i)};
  }

 private:
  std::string bridge_ns() const { return tag_ + "_br"; }

  template <class... A>
  static void run(fmt::format_string<A...> f, A&&... args) {
    const auto cmd = fmt::format(f, std::forward<A>(args)...);
    if (std::system((cmd + " 2>&1").c_str()) != 0) throw std::runtime_error("failed: " + cmd);
  }

  // Kills what still runs in the namespaces, then deletes them (their veths go with them).
  void cleanup() {
    const auto cmd = fmt::format(
        "for ns in $(ip netns list | awk '{{print $1}}' | grep '^{}_'); do "
        "ip netns pids $ns | xargs -r kill -9; ip netns del $ns; done 2>/dev/null",
        tag_);
    (void)!std::system(cmd.c_str());
  }

  std::string tag_;
  int subnet_;
  std::vector<std::string> hosts_;
};

}  // namespace oscar::test
