#include "identity_policy.hpp"

#include <algorithm>
#include <chrono>

#include "oscar/registry/clock_topics.hpp"
#include "oscar/registry/monitor_report_topic.hpp"
#include "oscar/security_files.hpp"
#include "oscar/topics.hpp"
#include "oscar/type_texts.hpp"

namespace oscar::security {
namespace {

namespace files = security_files;

// Topic names come from the topic catalogue, so permissions name what the processes really use;
// "*" stands for any module or channel (the topic is the catalogue's with that as its argument).
const std::string kAnyModulesConfig = topics::config("*").name;

void add(std::vector<std::string>& list, const std::string& topic) {
  if (std::find(list.begin(), list.end(), topic) == list.end()) list.push_back(topic);
}

// What every module process writes: its kernels' cues and pull replies, pull requests to the
// outputs its inputs are wired to, its configuration replies, state, heartbeat and wishes, and
// the IDL texts of its own types.
std::vector<std::string> module_topics(const SystemModule& m) {
  std::vector<std::string> out{topics::log().name};
  for (const auto& k : m.spec.kernels) {
    add(out, topics::cue(k.name + "/*"));
    add(out, topics::pull_reply(k.name + "/*").name);
  }
  for (const auto& k : m.spec.kernels) {
    for (const auto& [input, wiring] : k.inputs) {
      if (!wiring.source.empty()) add(out, topics::pull_request(wiring.source).name);
    }
  }
  add(out, topics::config_reply(m.spec.name).name);
  add(out, topics::module_state().name);
  add(out, topics::module_alive(std::chrono::milliseconds(1)).name);
  add(out, topics::sched_wishes().name);
  add(out, topics::module_types().name);
  return out;
}

// The coordinator also commands every module, publishes its plan and answers applets and swarm
// clients; the job_generator applet, which may run in its process, submits swarm jobs.
void add_coordinator_topics(std::vector<std::string>& out) {
  for (const auto& t :
       {kAnyModulesConfig, topics::applet_plan().name, topics::sched_reply().name,
        topics::sched_notice().name, topics::sched_command_reply().name, topics::swarm_reply().name,
        topics::swarm_status().name, topics::swarm_plan().name, topics::swarm_request().name}) {
    add(out, t);
  }
}

// A process of applets speaks the applet protocol to the coordinator (and may submit swarm jobs).
void add_applet_process_topics(std::vector<std::string>& out) {
  for (const auto& t :
       {topics::sched_hello().name, topics::sched_beat().name, topics::sched_call().name,
        topics::sched_command().name, topics::swarm_request().name}) {
    add(out, t);
  }
}

IdentityPolicy make(std::string name, std::vector<std::string> publish) {
  return {std::move(name), std::move(publish), {"*"}};
}

}  // namespace

std::vector<IdentityPolicy> identities_of(const SystemSpec& system) {
  const auto log = topics::log().name;
  // Boot sends the initial configuration and asks the registry (shutdown); the registry
  // suspends, resumes and re-applies configurations, launches and answers; the read-only
  // operator writes nothing.
  const std::vector<std::string> boot{log, kAnyModulesConfig, topics::registry_request().name};
  // The tools acting with boot's authority may also submit jobs and world changes to the swarm.
  auto operator_boot = boot;
  operator_boot.push_back(topics::swarm_request().name);
  std::vector<IdentityPolicy> all{
      make(files::kRegistry,
           {log, kAnyModulesConfig, topics::launch().name, topics::registry_reply().name,
            topics::system_state().name, topics::clock_echo().name}),
      make(files::kBoot, boot),
      make(files::kOperator, {}),
      make(files::kOperatorBoot, operator_boot),
  };
  for (const auto& h : system.hosts) {
    all.push_back(make(files::monitor_identity(h.name),
                       {log, topics::monitor_alive(std::chrono::milliseconds(1)).name,
                        topics::process_events().name, topics::monitor_children().name,
                        topics::clock_probe().name, topics::host_clocks().name}));
  }
  for (const auto& m : system.modules) {
    auto publish = module_topics(m);
    if (m.program == "oscar-coordinator") add_coordinator_topics(publish);
    if (m.program == "oscar-applet") add_applet_process_topics(publish);
    all.push_back(make(files::module_identity(m.spec.name), std::move(publish)));
  }
  return all;
}

}  // namespace oscar::security
