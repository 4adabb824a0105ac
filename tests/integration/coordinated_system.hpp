#pragma once
// The booted camera system of docs/coordinator.md with the coordinator's plan as published and
// a client that sends the applets' events (coordinator_test.cpp, coordinator_changes_test.cpp).
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "booted_system.hpp"
#include "oscar/config_client.hpp"
#include "oscar/coordinator/plan_json.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "source_tree.hpp"

namespace oscar::test {

// The example of docs/coordinator.md.
inline std::string camera_system() {
  std::ifstream in(oscar::testing::source_path("config/coordinator-camera.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The example with a module lease of 1 s instead of the default 300 ms: the tests that use it are
// about the coordinator, not about how soon a hung module is found, and under ThreadSanitizer a
// module's heartbeat missed 300 ms (the registry restarted the camera mid-test).
inline std::string camera_system_with_longer_lease() {
  auto yaml = camera_system();
  const std::string domain = "domain: 44\n";
  const auto at = yaml.find(domain);
  if (at == std::string::npos || yaml.find("\nlease:") != std::string::npos) {
    throw std::logic_error("the example changed: no '" + domain + "' line, or a lease already");
  }
  return yaml.insert(at + domain.size(), "lease: 1s\n");
}

// The booted camera system, the coordinator's plan as published, and a client that sends the
// applets' events with boot's authority.
class CoordinatedSystem {
 public:
  explicit CoordinatedSystem(const std::string& name,
                             const std::string& yaml = camera_system_with_longer_lease())
      : sys(name, yaml),
        plans_(sys.participant(), topics::applet_plan(),
               [this](const AppletPlan& p, const auto&) {
                 std::lock_guard lock(mutex_);
                 plan_ = p;
                 changed_.notify_all();
               }),
        client_(sys.participant(), "boot") {}

  // The first plan satisfying `pred`; fails the test after a generous wait.
  AppletPlan wait_plan(const std::function<bool(const AppletPlan&)>& pred, const char* what) {
    std::unique_lock lock(mutex_);
    if (changed_.wait_for(lock, std::chrono::seconds(30), [&] { return plan_ && pred(*plan_); })) {
      return *plan_;
    }
    ADD_FAILURE() << "the plan never showed " << what
                  << "; last: " << (plan_ ? coordinator::plan_json(*plan_) : "none")
                  << "\nboot output:\n"
                  << sys.boot_output();
    return plan_.value_or(AppletPlan{});
  }

  // The applet's entry in the plan: "process state", or "(none)".
  static std::string applet(const AppletPlan& p, const std::string& name) {
    for (const auto& a : p.applets()) {
      if (a.name() == name) return a.process() + " " + a.state();
    }
    return "(none)";
  }

  static std::vector<std::string> holders(const AppletPlan& p, const std::string& service) {
    for (const auto& s : p.services()) {
      if (s.name() == service) return s.holders();
    }
    return {"(no such service)"};
  }

  ConfigReply event(const std::string& applet, const std::string& what) {
    AppletEvent e;
    e.applet(applet);
    e.bundle("camera");
    e.event(what);
    return client_.command("coordinator", "coordinator", "applet", e);
  }

  ConfigReply command(const AppletEvent& e) {
    return client_.command("coordinator", "coordinator", "applet", e);
  }

  ::testing::AssertionResult accepted(const std::string& applet, const std::string& what) {
    const auto reply = event(applet, what);
    if (reply.ok()) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << applet << " " << what << ": " << reply.error();
  }

  ConfigReply event(const std::string& applet, const std::string& bundle, const std::string& what) {
    AppletEvent e;
    e.applet(applet);
    e.bundle(bundle);
    e.event(what);
    return client_.command("coordinator", "coordinator", "applet", e);
  }

  // The camera kernel's mode as the registry reports it reaches `mode`.
  void wait_cam_mode(const std::string& mode) { wait_mode("cam", mode); }
  // The mode of kernel `module` (named like its module) reaches `mode`.
  void wait_mode(const std::string& module, const std::string& mode) {
    sys.wait_for([&](const SystemState& st) {
      const auto* m = entry(st, module);
      const auto* k = m ? kernel_state(*m, module) : nullptr;
      return k && k->mode() == mode && m->status() == "running";
    });
  }

  // Boot's merged log shows `text` (the coordinator's and applets' lines reach it).
  ::testing::AssertionResult logged(const std::string& text) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < until) {
      if (sys.boot_output().find(text) != std::string::npos) {
        return ::testing::AssertionSuccess();
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return ::testing::AssertionFailure() << "boot's log never showed '" << text << "':\n"
                                         << sys.boot_output();
  }

  BootedSystem sys;

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<AppletPlan> plan_;
  TopicReader<AppletPlan, AppletPlanPubSubType> plans_;
  ConfigClient client_;
};

}  // namespace oscar::test
