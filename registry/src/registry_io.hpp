#pragma once
// The registry's DDS endpoints (internal): every callback posts an event to the run() thread.

#include <map>
#include <mutex>
#include <utility>

#include <oscar/configPubSubTypes.h>
#include <oscar/host_clockPubSubTypes.h>
#include <oscar/registryPubSubTypes.h>

#include "oscar/registry/monitor_report_topic.hpp"
#include "oscar/registry/registry.hpp"
#include "oscar/topic_io.hpp"

namespace oscar {

class Registry::Io {
 public:
  explicit Io(Registry& r);

  /// A request to the monitor of `host`; `restore` is the configuration a start restores.
  void send(LaunchKind kind, const std::string& host, long monitor_pid, const std::string& module,
            unsigned incarnation, const std::string& restore = "");
  /// Waits until every monitor has acknowledged the requests sent so far, at most `timeout`:
  /// the registry's last requests (LAUNCH_EXIT) would be lost if it exited before.
  void wait_until_delivered(std::chrono::milliseconds timeout);
  void reply(unsigned long long id, const std::string& error);
  void publish(const SystemState& state) { system_.write(state); }
  /// When the last heartbeat of that incarnation arrived (epoch if none did).
  Clock::time_point last_beat(const std::string& module, unsigned incarnation);

 private:
  using Handle = eprosima::fastdds::dds::InstanceHandle_t;
  Registry& r_;
  std::mutex handles_mutex_;
  std::map<Handle, std::pair<std::string, long>> monitor_handles_;     // -> host, pid
  std::map<Handle, std::pair<std::string, unsigned>> module_handles_;  // -> module, incarnation
  std::map<std::pair<std::string, unsigned>, Clock::time_point> beats_at_;
  // Monitors ignore a request id they have seen: a registry started after a crash must not
  // reuse its predecessor's, so ids count on from the wall clock at start (ns since the epoch).
  unsigned long long next_id_ = 0;

  TopicWriter<LaunchRequest, LaunchRequestPubSubType> launch_;
  TopicWriter<RegistryReply, RegistryReplyPubSubType> reply_;
  TopicWriter<SystemState, SystemStatePubSubType> system_;
  TopicReader<MonitorBeat, MonitorBeatPubSubType> monitors_;
  TopicReader<ProcessEvent, ProcessEventPubSubType> events_;
  TopicReader<ModuleState, ModuleStatePubSubType> states_;
  TopicReader<ModuleBeat, ModuleBeatPubSubType> beats_;
  TopicReader<RegistryRequest, RegistryRequestPubSubType> requests_;
  TopicReader<MonitorReport, MonitorReportPubSubType> reports_;
  // The monitors' clock probes, echoed at once from the reader's thread: the registry's own
  // loop would add its latency to the round trip (docs/boot.md, "Clocks").
  TopicWriter<ClockEcho, ClockEchoPubSubType> clock_echoes_;
  TopicReader<ClockProbe, ClockProbePubSubType> clock_probes_;
};

}  // namespace oscar
