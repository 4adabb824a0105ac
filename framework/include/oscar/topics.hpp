#pragma once
/// @file The topic catalogue: every topic OSCAR itself uses, with its name, its IDL type and the
/// QoS of its writers and readers, defined once. Modules, the registry, the monitors, boot and
/// the tools all take their endpoints from here, so the two sides of a topic cannot drift apart
/// (docs/architecture.md, "Topics and QoS classes").
///
/// Cue topics are the one exception to "QoS defined here": a cue topic's QoS is the class its
/// producing output declares (qos::cue_writer) and its readers follow it (qos::cue_reader).

#include <chrono>
#include <string>
#include <string_view>

#include <oscar/configPubSubTypes.h>
#include <oscar/coordinatorPubSubTypes.h>
#include <oscar/pullPubSubTypes.h>
#include <oscar/registryPubSubTypes.h>
#include <oscar/schedPubSubTypes.h>
#include <oscar/swarmPubSubTypes.h>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

namespace oscar {

/// One topic: its name, its IDL type (`T`, with Fast DDS's type support `PubSubType`) and the
/// QoS every writer and every reader of it uses.
template <class T, class PubSubType>
struct TopicSpec {
  using Sample = T;
  using TypeSupport = PubSubType;
  std::string name;
  eprosima::fastdds::dds::DataWriterQos writer_qos;
  eprosima::fastdds::dds::DataReaderQos reader_qos;
};

namespace topics {

/// "oscar/cue/": the prefix of every cue topic.
inline constexpr std::string_view kCuePrefix = "oscar/cue/";
/// The cue topic of output `address` ("kernel/channel"): "oscar/cue/kernel/channel".
std::string cue(std::string_view address);
/// True for a cue topic's name.
bool is_cue(std::string_view topic);

/// Pull requests to output `address` ("kernel/channel") and the producer's replies: reliable,
/// volatile, 16 deep, without data sharing (each puller reads only its own replies through a
/// content filter, which the producer's writer evaluates).
TopicSpec<PullRequest, PullRequestPubSubType> pull_request(std::string_view address);
TopicSpec<PullReply, PullReplyPubSubType> pull_reply(std::string_view address);

/// How many configuration commands a module's reader holds that its listener has not taken.
inline constexpr int kConfigReaderDepth = 64;
/// Configuration commands to `module`: reliable; the writer keeps all, the module's reader the
/// last kConfigReaderDepth. A writer that outruns the module's listener has the oldest commands
/// not yet taken replaced (whoever wrote them) instead of growing the reader without bound.
TopicSpec<ConfigCommand, ConfigCommandPubSubType> config(const std::string& module);
/// `module`'s replies to configuration commands (state class, 64 deep: a client that matches
/// late still gets its reply).
TopicSpec<ConfigReply, ConfigReplyPubSubType> config_reply(const std::string& module);
/// Every module's and tool's log records (reliable, transient-local, the last 100 per writer:
/// a reader that matches a writer late still gets its recent lines).
TopicSpec<LogRecord, LogRecordPubSubType> log();
/// Each module's announcement and state (state class: late joiners get the latest).
TopicSpec<ModuleState, ModuleStatePubSubType> module_state();
/// Each module's heartbeat, with liveliness `lease` (manual by topic).
TopicSpec<ModuleBeat, ModuleBeatPubSubType> module_alive(std::chrono::milliseconds lease);
/// Each monitor's heartbeat, with liveliness `lease`.
TopicSpec<MonitorBeat, MonitorBeatPubSubType> monitor_alive(std::chrono::milliseconds lease);
/// What the monitors saw of their processes: started, exited, failed to start (256 deep).
TopicSpec<ProcessEvent, ProcessEventPubSubType> process_events();
/// The registry's launch requests to the monitors.
TopicSpec<LaunchRequest, LaunchRequestPubSubType> launch();
/// Requests to the registry (restart, shutdown) and its replies.
TopicSpec<RegistryRequest, RegistryRequestPubSubType> registry_request();
TopicSpec<RegistryReply, RegistryReplyPubSubType> registry_reply();
/// The whole system's state, as the registry publishes it (keep last 1).
TopicSpec<SystemState, SystemStatePubSubType> system_state();
/// The coordinator's plan: services, holders, applets (keep last 1; `oscar applets ps`).
TopicSpec<AppletPlan, AppletPlanPubSubType> applet_plan();

/// The applet protocol between the coordinator and applets in other processes
/// (docs/coordinator.md): reliable, volatile, keep all (nothing dropped; a restarted process
/// starts afresh and announces itself), except the beats (a stream, 16 deep).
/// An applet's announcement with all it asks for.
TopicSpec<SchedHello, SchedHelloPubSubType> sched_hello();
/// What a module's kernels wish from the coordinator (reliable, transient-local, the last per
/// module process).
TopicSpec<SchedModuleWishes, SchedModuleWishesPubSubType> sched_wishes();
/// An applet's heartbeat from its loop (the coordinator's lease).
TopicSpec<SchedBeat, SchedBeatPubSubType> sched_beat();
/// An applet's scheduler calls and the coordinator's replies.
TopicSpec<SchedCall, SchedCallPubSubType> sched_call();
TopicSpec<SchedReply, SchedReplyPubSubType> sched_reply();
/// The coordinator's notifications to applets.
TopicSpec<SchedNotice, SchedNoticePubSubType> sched_notice();
/// An applet's commands to modules through the coordinator, and their replies.
TopicSpec<SchedCommand, SchedCommandPubSubType> sched_command();
TopicSpec<SchedCommandReply, SchedCommandReplyPubSubType> sched_command_reply();

/// The live swarm (docs/swarm.md): jobs submitted to the coordinator (reliable, volatile, keep
/// all), its replies (transient-local, the last 64), its status (keep last 1; `oscar swarm
/// status`) and its committed plan (keep last 1; `oscar swarm snapshot`).
TopicSpec<SwarmRequest, SwarmRequestPubSubType> swarm_request();
TopicSpec<SwarmReply, SwarmReplyPubSubType> swarm_reply();
TopicSpec<SwarmStatus, SwarmStatusPubSubType> swarm_status();
TopicSpec<SwarmPlan, SwarmPlanPubSubType> swarm_plan();

}  // namespace topics
}  // namespace oscar
