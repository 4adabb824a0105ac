#include "registry_io.hpp"

#include "oscar/registry/clock_topics.hpp"
#include "oscar/time.hpp"
#include "oscar/topics.hpp"

#include <oscar/configPubSubTypes.h>

namespace oscar {

Registry::Io::Io(Registry& r)
    : r_(r),
      next_id_(static_cast<unsigned long long>(wall_now())),
      launch_(r.participant_, topics::launch()),
      reply_(r.participant_, topics::registry_reply()),
      system_(r.participant_, topics::system_state()),
      monitors_(
          r.participant_, topics::monitor_alive(r.system_.lease),
          [this](const MonitorBeat& b, const auto& info) {
            {
              std::lock_guard lock(handles_mutex_);
              monitor_handles_[info.publication_handle] = {b.host(), b.pid()};
            }
            r_.post([this, b] { r_.on_monitor_beat(b); });
          },
          [this](const Handle& h) {
            std::lock_guard lock(handles_mutex_);
            const auto it = monitor_handles_.find(h);
            if (it == monitor_handles_.end()) return;
            const auto [host, pid] = it->second;
            r_.post([this, host, pid] { r_.on_monitor_lost(host, pid); });
          }),
      events_(r.participant_, topics::process_events(),
              [this](const ProcessEvent& e, const auto&) {
                r_.post([this, e] { r_.on_process_event(e); });
              }),
      states_(r.participant_, topics::module_state(),
              [this](const ModuleState& s, const auto&) {
                r_.post([this, s] { r_.on_module_state(s); });
              }),
      beats_(
          r.participant_, topics::module_alive(r.system_.lease),
          [this](const ModuleBeat& b, const auto& info) {
            std::lock_guard lock(handles_mutex_);
            module_handles_[info.publication_handle] = {b.module_name(), b.incarnation()};
            beats_at_[{b.module_name(), b.incarnation()}] = Clock::now();
          },
          [this](const Handle& h) {
            std::lock_guard lock(handles_mutex_);
            const auto it = module_handles_.find(h);
            if (it == module_handles_.end()) return;
            const auto [module, incarnation] = it->second;
            r_.post([this, module, incarnation] { r_.on_module_lost(module, incarnation); });
          }),
      requests_(r.participant_, topics::registry_request(),
                [this](const RegistryRequest& q, const auto& info) {
                  // Where it really comes from: the modules living in the writer's process.
                  auto origin =
                      r_.participant_.modules_in_process_of(info.sample_identity.writer_guid());
                  r_.post([this, q, origin] { r_.on_request(q, origin); });
                }),
      reports_(r.participant_, topics::monitor_children(),
               [this](const MonitorReport& report, const auto&) {
                 r_.post([this, report] { r_.on_monitor_report(report); });
               }),
      clock_echoes_(r.participant_, topics::clock_echo()),
      clock_probes_(r.participant_, topics::clock_probe(),
                    [this](const ClockProbe& p, const auto&) {
                      const auto t2 = wall_now();  // first, before anything else delays it
                      ClockEcho e;
                      e.host(p.host());
                      e.monitor_pid(p.monitor_pid());
                      e.seq(p.seq());
                      e.t1_ns(p.t1_ns());
                      e.t2_ns(t2);
                      e.t3_ns(wall_now());  // last, just before it leaves
                      clock_echoes_.write(e);
                    }) {}

void Registry::Io::send(LaunchKind kind, const std::string& host, long monitor_pid,
                        const std::string& module, unsigned incarnation,
                        const std::string& restore) {
  LaunchRequest q;
  q.id(next_id_++);
  q.host(host);
  q.monitor_pid(static_cast<std::int32_t>(monitor_pid));
  q.kind(kind);
  q.module_name(module);
  q.incarnation(incarnation);
  q.restore(restore);
  launch_.write(q);
}

void Registry::Io::wait_until_delivered(std::chrono::milliseconds timeout) {
  const auto ms = timeout.count();
  launch_.dds_writer().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(
      static_cast<std::int32_t>(ms / 1000), static_cast<std::uint32_t>(ms % 1000) * 1000000u));
}

Registry::Clock::time_point Registry::Io::last_beat(const std::string& module,
                                                    unsigned incarnation) {
  std::lock_guard lock(handles_mutex_);
  const auto it = beats_at_.find({module, incarnation});
  return it == beats_at_.end() ? Clock::time_point{} : it->second;
}

void Registry::Io::reply(unsigned long long id, const std::string& error) {
  RegistryReply rep;
  rep.id(id);
  rep.ok(error.empty());
  rep.error(error);
  reply_.write(rep);
}

}  // namespace oscar
