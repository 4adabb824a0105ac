#include "system_graph.hpp"

#include <set>

#include <nlohmann/json.hpp>

#include "oscar/idl_type_info.hpp"
#include "oscar/topics.hpp"

OSCAR_DECLARE_IDL_TYPE(oscar, SystemState)

namespace oscar::bridge {
using json = nlohmann::ordered_json;

namespace {
json kernel_json(const KernelState& k, std::map<std::string, std::vector<std::string>>& consumers) {
  json inputs = json::array();
  for (const auto& wire : k.inputs()) {  // "input=kernel/channel"
    const auto eq = wire.find('=');
    if (eq == std::string::npos) continue;
    const auto source = wire.substr(eq + 1);
    inputs.push_back({{"input", wire.substr(0, eq)}, {"source", source}});
    consumers[source].push_back(k.name() + "." + wire.substr(0, eq));
  }
  return {{"name", k.name()},         {"type", k.type()},
          {"mode", k.mode()},         {"cycle_ms", static_cast<double>(k.cycle_ns()) / 1e6},
          {"trigger", k.trigger()},   {"stub", k.stub()},
          {"params", k.params()},     {"inputs", inputs},
          {"cycles", k.cycles()},     {"published", k.published()},
          {"failures", k.failures()}, {"last_failure", k.last_failure()}};
}
}  // namespace

SystemState system_state_from_cdr(const std::vector<std::uint8_t>& cdr) {
  return *std::static_pointer_cast<SystemState>(internal::deserialize_idl<SystemState>(cdr));
}

std::string system_graph_json(
    const SystemState& state,
    const std::map<std::string, DdsParticipant::DiscoveredWriter>& writers,
    const std::vector<SideChannelActivity>& side_channels) {
  std::map<std::string, std::vector<std::string>> consumers;  // "kernel/channel" -> "k.input"
  std::set<std::string> kernels;
  json modules = json::array();
  for (const auto& m : state.modules()) {
    json ks = json::array();
    for (const auto& k : m.state().kernels()) {
      kernels.insert(k.name());
      ks.push_back(kernel_json(k, consumers));
    }
    modules.push_back({{"name", m.name()},
                       {"host", m.host()},
                       {"pid", m.pid()},
                       {"status", m.status()},
                       {"suspended", m.state().suspended()},
                       {"restarts", m.restarts()},
                       {"last_failure", m.last_failure()},
                       {"cues_per_s", m.cues_per_s()},
                       {"kernels", ks}});
  }
  // Channels: every wired source, and every cue topic a kernel of the system writes.
  std::set<std::string> sources;
  for (const auto& [source, list] : consumers) sources.insert(source);
  for (const auto& [topic, w] : writers) {
    if (!topics::is_cue(topic) || w.alive == 0) continue;
    const auto source = topic.substr(topics::kCuePrefix.size());
    if (kernels.contains(source.substr(0, source.find('/')))) sources.insert(source);
  }
  json channels = json::array();
  for (const auto& source : sources) {
    const auto topic = topics::cue(source);
    const auto w = writers.find(topic);
    channels.push_back({{"source", source},
                        {"topic", topic},
                        {"type", w == writers.end() || w->second.alive == 0 ? "" : w->second.type},
                        {"producer", source.substr(0, source.find('/'))},
                        {"consumers", consumers[source]}});
  }
  json bridge = json::array();
  for (const auto& s : side_channels) {
    bridge.push_back({{"topic", s.topic},
                      {"source", s.source},
                      {"subscribers", s.subscribers},
                      {"converted", s.converted},
                      {"skipped", s.skipped}});
  }
  return json{{"system", state.system()},
              {"state", state.state()},
              {"message", state.message()},
              {"stamp_ns", state.stamp_ns()},
              {"hosts_lost", state.hosts_lost()},
              {"modules", modules},
              {"channels", channels},
              {"side_channels", bridge}}
      .dump();
}

}  // namespace oscar::bridge
