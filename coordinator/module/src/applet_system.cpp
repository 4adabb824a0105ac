#include "oscar/coordinator/applet_system.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "oscar/coordinator/applet.hpp"

namespace oscar::coordinator {

namespace {
// A service in the applet scheduler's vocabulary: its name, access and needs.
YAML::Node scheduler_service(const ServiceSpec& svc) {
  YAML::Node s;
  s["name"] = svc.name;
  s["exclusive_only"] = svc.exclusive_only;
  for (const auto& n : svc.needs) {
    YAML::Node d;
    d["service"] = n.service;
    d["access"] = n.exclusive ? "exclusive" : "shared";
    s["depends_on"].push_back(d);
  }
  return s;
}

// An applet in the scheduler's vocabulary: its entry without what is the coordinator's (type)
// and where it runs (process, host). The nodes keep their lines for the scheduler's messages.
YAML::Node scheduler_applet(const AppletSpec& a) {
  YAML::Node applet;
  for (const auto& kv : a.node) {
    const auto key = kv.first.as<std::string>();
    if (key != "type" && key != "process" && key != "host") applet[kv.first] = kv.second;
  }
  return applet;
}
}  // namespace

applets::SystemConfig applet_system(const SystemSpec& system) {
  // The applet scheduler's own YAML vocabulary, assembled from the system file's nodes (which
  // keep their lines, so its messages point into the system file).
  YAML::Node doc;
  doc["services"] = YAML::Node(YAML::NodeType::Sequence);
  for (const auto& svc : system.services) doc["services"].push_back(scheduler_service(svc));
  if (!system.coordinator) return applets::load_system(doc, system.file);
  const auto& c = *system.coordinator;
  if (c.scheduler.IsDefined() && !c.scheduler.IsNull()) doc["scheduler"] = c.scheduler;
  doc["applets"] = YAML::Node(YAML::NodeType::Sequence);
  for (const auto& a : c.applets) doc["applets"].push_back(scheduler_applet(a));
  // A kernel's wishes are the bundles of an applet named after it (docs/coordinator.md).
  for (const auto& w : c.wishes) {
    YAML::Node applet;
    applet["name"] = w.applet();
    applet["bundles"] = w.bundles;
    doc["applets"].push_back(applet);
  }
  return applets::load_system(doc, system.file);
}

YAML::Node scheduler_doc(const SystemAddition& addition) {
  YAML::Node doc;
  if (!addition.services.empty()) {
    doc["services"] = YAML::Node(YAML::NodeType::Sequence);
    for (const auto& svc : addition.services) doc["services"].push_back(scheduler_service(svc));
  }
  if (!addition.applets.empty()) {
    doc["applets"] = YAML::Node(YAML::NodeType::Sequence);
    for (const auto& a : addition.applets) doc["applets"].push_back(scheduler_applet(a));
  }
  return doc;
}

namespace {
// Applets made only to check them: nothing runs, so nothing calls the gateway.
class NoGateway final : public AppletGateway {
 public:
  ConfigReply command(const std::string&, const std::string&, const std::string&,
                      const std::string&, const std::string&, const std::string&,
                      std::vector<std::uint8_t>) override {
    throw std::logic_error("an applet commanded a module while being checked");
  }
  ConfigReply trigger(const std::string&, const std::string&, const std::string&,
                      const std::string&) override {
    throw std::logic_error("an applet triggered a module while being checked");
  }
  std::string bundle_name(applets::BundleId) const override { return {}; }
};
}  // namespace

void check_applets(const SystemSpec& system, const std::vector<std::string>& plugin_path) {
  auto config = applet_system(system);
  if (!system.coordinator) return;
  NoGateway gateway;
  for (const auto& a : system.coordinator->applets) {
    AppletSetup setup(a.name, config.applet_params[a.name], gateway);
    try {
      make_applet(a.type, setup, plugin_path);
    } catch (const std::exception& e) {
      throw std::invalid_argument(fmt::format("{}: applet '{}': {}", a.where, a.name, e.what()));
    }
  }
}

}  // namespace oscar::coordinator
