#include "oscar/topics.hpp"

#include "oscar/topic_io.hpp"

namespace oscar::topics {

std::string cue(std::string_view address) { return std::string(kCuePrefix).append(address); }

bool is_cue(std::string_view topic) { return topic.starts_with(kCuePrefix); }

namespace {
template <class Qos>
Qos without_data_sharing(Qos q) {
  q.data_sharing().off();
  return q;
}
std::string pull_topic(std::string_view address, std::string_view end) {
  return std::string("oscar/pull/").append(address).append("/").append(end);
}
}  // namespace

TopicSpec<PullRequest, PullRequestPubSubType> pull_request(std::string_view address) {
  return {pull_topic(address, "request"), without_data_sharing(qos::stream_writer(16)),
          without_data_sharing(qos::stream_reader(16))};
}

TopicSpec<PullReply, PullReplyPubSubType> pull_reply(std::string_view address) {
  return {pull_topic(address, "reply"), without_data_sharing(qos::stream_writer(16)),
          without_data_sharing(qos::stream_reader(16))};
}

TopicSpec<ConfigCommand, ConfigCommandPubSubType> config(const std::string& module) {
  // The writer keeps every command until the module has it; the module's reader keeps at most
  // kConfigReaderDepth not yet taken (its listener takes them at once and rate-limits writers).
  return {"oscar/config/" + module, qos::command_writer(), qos::request_reader(kConfigReaderDepth)};
}

TopicSpec<ConfigReply, ConfigReplyPubSubType> config_reply(const std::string& module) {
  return {"oscar/config_reply/" + module, qos::state_writer(64), qos::state_reader(64)};
}

TopicSpec<LogRecord, LogRecordPubSubType> log() {
  // Transient-local: a reader that discovers a module after its first lines (boot, just after
  // the module started, under load; `oscar log` started later) still gets its last 100.
  return {"oscar/log", qos::state_writer(100), qos::state_reader(100)};
}

TopicSpec<ModuleState, ModuleStatePubSubType> module_state() {
  // Each module has a writer of its own that keeps its latest state; the registry's reader
  // keeps the recent states of all.
  return {"oscar/registry/module_state", qos::state_writer(1), qos::state_reader(64)};
}

TopicSpec<ModuleBeat, ModuleBeatPubSubType> module_alive(std::chrono::milliseconds lease) {
  return {"oscar/registry/alive", qos::beat_writer(lease), qos::beat_reader(lease)};
}

TopicSpec<MonitorBeat, MonitorBeatPubSubType> monitor_alive(std::chrono::milliseconds lease) {
  return {"oscar/registry/monitor", qos::beat_writer(lease), qos::beat_reader(lease)};
}

TopicSpec<ProcessEvent, ProcessEventPubSubType> process_events() {
  return {"oscar/registry/process", qos::state_writer(256), qos::state_reader(256)};
}

TopicSpec<LaunchRequest, LaunchRequestPubSubType> launch() {
  return {"oscar/registry/launch", qos::state_writer(64), qos::state_reader(64)};
}

TopicSpec<RegistryRequest, RegistryRequestPubSubType> registry_request() {
  return {"oscar/registry/request", qos::state_writer(16), qos::state_reader(16)};
}

TopicSpec<RegistryReply, RegistryReplyPubSubType> registry_reply() {
  return {"oscar/registry/reply", qos::state_writer(16), qos::state_reader(16)};
}

TopicSpec<SystemState, SystemStatePubSubType> system_state() {
  return {"oscar/system/state", qos::state_writer(1), qos::state_reader(1)};
}

TopicSpec<AppletPlan, AppletPlanPubSubType> applet_plan() {
  return {"oscar/coordinator/plan", qos::state_writer(1), qos::state_reader(1)};
}

TopicSpec<SchedHello, SchedHelloPubSubType> sched_hello() {
  return {"oscar/sched/hello", qos::command_writer(), qos::command_reader()};
}

TopicSpec<SchedModuleWishes, SchedModuleWishesPubSubType> sched_wishes() {
  // The reader keeps more than one: after a restart it gets the last set of every module at
  // once, and keyless samples share one history.
  return {"oscar/sched/wishes", qos::state_writer(1), qos::state_reader(256)};
}

TopicSpec<SchedBeat, SchedBeatPubSubType> sched_beat() {
  return {"oscar/sched/beat", qos::stream_writer(16), qos::stream_reader(16)};
}

TopicSpec<SchedCall, SchedCallPubSubType> sched_call() {
  return {"oscar/sched/call", qos::command_writer(), qos::command_reader()};
}

TopicSpec<SchedReply, SchedReplyPubSubType> sched_reply() {
  return {"oscar/sched/reply", qos::command_writer(), qos::command_reader()};
}

TopicSpec<SchedNotice, SchedNoticePubSubType> sched_notice() {
  return {"oscar/sched/notice", qos::command_writer(), qos::command_reader()};
}

TopicSpec<SchedCommand, SchedCommandPubSubType> sched_command() {
  return {"oscar/sched/command", qos::command_writer(), qos::command_reader()};
}

TopicSpec<SchedCommandReply, SchedCommandReplyPubSubType> sched_command_reply() {
  return {"oscar/sched/command_reply", qos::command_writer(), qos::command_reader()};
}

TopicSpec<SwarmRequest, SwarmRequestPubSubType> swarm_request() {
  return {"oscar/swarm/request", qos::command_writer(), qos::command_reader()};
}

TopicSpec<SwarmReply, SwarmReplyPubSubType> swarm_reply() {
  // Transient-local: a reader matches the coordinator's writer before that writer has matched
  // the reader, so a reply written in between would be lost to a volatile reader, and the
  // requester would wait for it in vain. Kept replies reach a late reader; it takes its own.
  return {"oscar/swarm/reply", qos::state_writer(64), qos::state_reader(64)};
}

TopicSpec<SwarmStatus, SwarmStatusPubSubType> swarm_status() {
  return {"oscar/swarm/status", qos::state_writer(1), qos::state_reader(1)};
}

TopicSpec<SwarmPlan, SwarmPlanPubSubType> swarm_plan() {
  return {"oscar/swarm/plan", qos::state_writer(1), qos::state_reader(1)};
}

}  // namespace oscar::topics
