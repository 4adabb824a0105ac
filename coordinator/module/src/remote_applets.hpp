#pragma once
// The coordinator's side of applets in other processes (not installed; docs/coordinator.md,
// "Applets in other processes"). Each such applet keeps its slot in the coordinator's Runtime,
// without a thread: its scheduler calls arrive on oscar/sched/call and are made on the Runtime's
// scheduler, its notifications leave on oscar/sched/notice, its commands are forwarded like a
// local applet's. Its process announces it (hello) with all it asks for and beats from the
// applet's loop; when the beats stop for longer than the lease, its bundles are taken (released)
// as a crashed local applet's are, and the next hello asks for them again.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <oscar/schedPubSubTypes.h>

#include "oscar/applets/runtime.hpp"
#include "oscar/coordinator/applet.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/registry/system_spec.hpp"
#include "oscar/topic_io.hpp"

namespace oscar::coordinator {

class RemoteApplets {
 public:
  /// Applets the system file does not configure, which join from other processes: `join` adds
  /// one (its hello's spec, seed 000 §4.1.1) and returns why not; it calls adopt(). `leave`
  /// removes one whose lease ran out (it calls forget()). Both are called from the worker
  /// thread, with no lock of this class held.
  struct Membership {
    std::function<std::optional<std::string>(const std::string& applet, const std::string& process,
                                             const std::string& spec)>
        join;
    std::function<void(const std::string& applet)> leave;
  };

  /// Makes every applet of `system` with a `process:` remote in `runtime` (before it starts).
  /// `gateway` forwards their commands; `changed` is called after every change of the plan that
  /// a remote applet made (the coordinator publishes the plan).
  RemoteApplets(const SystemSpec& system, applets::Runtime& runtime, AppletGateway& gateway,
                DdsParticipant& participant, std::function<void()> changed,
                Membership membership = {});
  ~RemoteApplets();
  RemoteApplets(const RemoteApplets&) = delete;
  RemoteApplets& operator=(const RemoteApplets&) = delete;

  void start();
  void stop();

  /// Whether the applet runs in another process.
  bool remote(const std::string& applet) const;
  /// What the runtime hands an applet's notifications to (Runtime::add's runner): they are
  /// queued for its process.
  std::function<void(const applets::Notification&)> forwarder(const std::string& applet);
  /// A joining applet was added to the runtime as `id`: it is remote from now on, announced
  /// by the hello that is being handled.
  void adopt(const std::string& applet, applets::AppletId id, const std::string& process);
  /// The applet was removed. With `refuse_session`, its process's present session may not join
  /// again (an operator removed it; a new start of the process may).
  void forget(const std::string& applet, bool refuse_session);
  /// Whether the applet joined by its hello (not configured in the system file).
  bool joined(const std::string& applet) const;
  /// What the plan shows of a remote applet: its process, and "absent" (not announced, or its
  /// lease ran out) or "crashed" when it is not taking part; nullopt when it is.
  struct Seen {
    std::string process;
    std::optional<std::string> state;
  };
  Seen seen(const std::string& applet) const;
  /// Passes an operator's event (AppletEvent: request, release, trigger, yield, set_priority,
  /// set_deadline, negotiate, crash) for a bundle to the remote applet, which makes it its own
  /// call, and waits until the applet says it did (event_done). Returns why not, if it cannot
  /// or the applet's call was refused.
  std::optional<std::string> event(const AppletEvent& event);

 private:
  struct Applet {
    applets::AppletId id = 0;
    std::string process;  // from the system file until a hello says otherwise
    std::uint64_t session = 0;
    bool present = false;
    bool crashed = false;
    bool joined = false;  // added by its hello's spec: removed when its lease runs out
    std::chrono::steady_clock::time_point last_beat;
    std::chrono::steady_clock::time_point last_announce_asked;
  };
  struct Outgoing {  // a notification to send, or a notice of the protocol's own
    std::string applet;
    std::optional<applets::Notification> notification;
    SchedNotice notice;
  };

  void worker();
  void commands();
  void on_hello(const SchedHello& hello);
  void on_call(const SchedCall& call);
  void on_beat(const SchedBeat& beat);
  void check_leases();
  // Releases every bundle of the applet (lease lost, crash, a new session).
  void take_bundles(applets::AppletId id);
  // The applet's bundle states, stamped (under the runtime's lock).
  void stamp(applets::Scheduler& s, applets::AppletId id, std::uint64_t& seq,
             std::vector<SchedBundleState>& states);
  void send(Outgoing out);
  bool current(const std::string& applet, std::uint64_t session);

  const SystemSpec& system_;
  applets::Runtime& runtime_;
  AppletGateway& gateway_;
  std::function<void()> changed_;
  Membership membership_;
  const std::chrono::milliseconds lease_;
  const std::uint64_t coordinator_id_;
  std::uint64_t state_seq_ = 0;  // under the runtime's lock

  mutable std::mutex mutex_;  // what follows
  std::condition_variable wake_;
  std::map<std::string, Applet> applets_;
  std::map<std::string, std::uint64_t> refused_;  // applet -> a session that may not join
  std::map<std::string, std::chrono::steady_clock::time_point> unknown_asked_;  // by applet
  std::deque<std::function<void()>> inbound_;  // hellos and calls, in arrival order
  std::deque<SchedCommand> commands_;
  std::deque<Outgoing> outgoing_;
  bool stopping_ = false;
  bool started_ = false;
  std::uint64_t next_event_id_ = 1;
  // Operator's events sent to applets, until their event_done: nullopt while pending, then
  // the applet's error ("" if its call was taken).
  std::map<std::uint64_t, std::optional<std::string>> events_;
  std::condition_variable events_done_;

  TopicWriter<SchedReply, SchedReplyPubSubType> reply_writer_;
  TopicWriter<SchedNotice, SchedNoticePubSubType> notice_writer_;
  TopicWriter<SchedCommandReply, SchedCommandReplyPubSubType> command_reply_writer_;
  std::unique_ptr<TopicReader<SchedHello, SchedHelloPubSubType>> hello_reader_;
  std::unique_ptr<TopicReader<SchedBeat, SchedBeatPubSubType>> beat_reader_;
  std::unique_ptr<TopicReader<SchedCall, SchedCallPubSubType>> call_reader_;
  std::unique_ptr<TopicReader<SchedCommand, SchedCommandPubSubType>> command_reader_;
  std::thread worker_;
  std::thread commands_thread_;
};

}  // namespace oscar::coordinator
