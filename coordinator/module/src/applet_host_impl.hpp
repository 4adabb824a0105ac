#pragma once
// The AppletHost's implementation (not installed): applet_host_setup.cpp makes and hosts the
// applets (the system file's and joining ones), applet_host.cpp runs them against the
// coordinator over DDS.

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "oscar/applets/config.hpp"
#include "oscar/coordinator/applet_host.hpp"
#include "oscar/coordinator/applet_system.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "sched_wire.hpp"

namespace oscar::coordinator {
namespace host_detail {

using applets::AppletId;
using applets::BundleId;
using applets::Notification;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

inline constexpr milliseconds kSlice{20};          // waits are cut into slices that keep beating
inline constexpr milliseconds kHelloAgain{300};    // a hello not welcomed yet is sent again
inline constexpr milliseconds kCallTimeout{3000};  // a scheduler call's reply
// A command's reply (the coordinator may first configure the providers, then the module answers).
inline constexpr milliseconds kCommandTimeout{10000};

}  // namespace host_detail

using namespace host_detail;  // NOLINT: this header's own names, in its two sources only

class AppletHost::Impl final : public AppletGateway {
 public:
  Impl(const SystemSpec& system, DdsParticipant& participant, const std::vector<std::string>& names,
       std::string process, const std::vector<std::string>& plugin_path,
       const YAML::Node& joining = {}, const std::string& joining_file = {});
  ~Impl() override;
  void start();
  void stop();

  ConfigReply command(const std::string& applet, const std::string& service,
                      const std::string& module, const std::string& kernel,
                      const std::string& command, const std::string& type,
                      std::vector<std::uint8_t> cdr) override;
  ConfigReply trigger(const std::string& applet, const std::string& service,
                      const std::string& module, const std::string& kernel) override;
  std::string bundle_name(BundleId bundle) const override {
    return config_.model.bundle(bundle).name;
  }

 private:
  class Context;
  // Sends an applet's command or trigger to the coordinator and waits for its reply.
  ConfigReply send(SchedCommand command);
  struct Chain {  // a chain of negotiation rounds under way (applet thread only)
    std::shared_ptr<const applets::NegotiationRound> next;
    Clock::time_point round_started;
    std::uint64_t step = 0;
    int rounds = 0;
  };
  struct Settings {  // what the applet set on a bundle: announced again with its request
    std::optional<int> priority;
    std::optional<applets::Deadline> deadline;
  };
  struct Hosted {
    std::string name;
    std::string spec;  // a joining applet's entry (its hello carries it); empty: the file's
    AppletId id = 0;
    bool fail_stop = false;
    std::unique_ptr<Applet> applet;
    std::uint64_t session = 0;
    // Under the host's mutex:
    bool welcomed = false;
    bool crashed = false;  // its code threw: it says nothing more
    Clock::time_point last_hello{}, last_beat{};
    std::uint64_t coordinator = 0, state_seq = 0;
    std::map<std::string, SchedBundleState> bundles;  // the coordinator's view, latest
    std::map<std::string, bool> requested;            // what it asks for (true) and has set
    std::map<std::string, Settings> settings;
    std::deque<SchedNotice> notices;  // for the applet's thread
    std::uint64_t next_seq = 1;
    std::map<std::uint64_t, SchedReply> replies;
    std::map<std::uint64_t, SchedCommandReply> command_replies;
    std::condition_variable cv;
    // The applet's thread only:
    std::optional<BundleId> reacting_to_revocation;
    std::map<BundleId, Chain> negotiations;
    std::uint64_t steps = 0;
    std::thread thread;
  };

  Hosted& hosted(const std::string& applet);
  // Makes the applet `name` of type `type` (`where` names its entry in messages) and hosts it.
  void host(const std::string& name, const std::string& type, const std::string& where,
            const std::vector<std::string>& plugin_path, std::string spec);
  // Reads the applets that join the running system (AppletHost's `joining`) into the model.
  void read_joining(const YAML::Node& joining, const std::string& file,
                    const std::vector<std::string>& plugin_path);
  void applet_main(Hosted& h);
  // Sends a hello while not welcomed, else a beat when one is due (any thread of the applet).
  void pump(Hosted& h);
  // Waits until `ready` (under the lock) or `timeout`, beating meanwhile. False on timeout or stop.
  bool wait(Hosted& h, std::unique_lock<std::mutex>& lock, Clock::duration timeout,
            const std::function<bool()>& ready);
  void apply_state(Hosted& h, std::uint64_t coordinator, std::uint64_t seq,
                   const std::vector<SchedBundleState>& bundles);
  // A scheduler call; nullopt when the coordinator is not reachable now (the applet's wishes
  // are announced again when it is).
  std::optional<SchedReply> call(Hosted& h, SchedCall c);
  void on_notice(const SchedNotice& n);
  void on_reply(const SchedReply& r);
  void on_command_reply(const SchedCommandReply& r);
  Notification notification_of(const Hosted& h, const SchedNotice& n) const;
  std::optional<Notification> run_round(Context& ctx, Hosted& h, BundleId bundle,
                                        const applets::NegotiationRound& round);
  void run_negotiations(Context& ctx, Hosted& h);
  // Applies an operator's event (a notice of kind event) as the applet's own call and tells the
  // coordinator (event_done, with the refusal if any). False for "crash": the caller throws.
  bool apply_event(Context& ctx, Hosted& h, const SchedNotice& n);

  const SystemSpec& system_;
  DdsParticipant& participant_;  // the applets' cue feeds read through it
  applets::SystemConfig config_;
  std::string process_;
  milliseconds beat_every_;
  std::map<std::string, std::unique_ptr<Hosted>> hosted_;
  mutable std::mutex mutex_;
  bool stopping_ = false;
  bool started_ = false;
  TopicWriter<SchedHello, SchedHelloPubSubType> hello_writer_;
  TopicWriter<SchedBeat, SchedBeatPubSubType> beat_writer_;
  TopicWriter<SchedCall, SchedCallPubSubType> call_writer_;
  TopicWriter<SchedCommand, SchedCommandPubSubType> command_writer_;
  std::unique_ptr<TopicReader<SchedNotice, SchedNoticePubSubType>> notice_reader_;
  std::unique_ptr<TopicReader<SchedReply, SchedReplyPubSubType>> reply_reader_;
  std::unique_ptr<TopicReader<SchedCommandReply, SchedCommandReplyPubSubType>>
      command_reply_reader_;
};

}  // namespace oscar::coordinator
