#pragma once
// Pull transfer across processes (docs/kernels.md): a consumer's request reaches the producer's
// frame, which answers from the output's ring buffer with the cues serialized as CDR. Replies to
// all consumers share the output's reply topic; each consumer reads it through a content filter
// on the requester, which the producer's writer evaluates, so a reply travels to its asker only.

#include <atomic>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <variant>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>

#include "held_pulls.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/input.hpp"
#include "oscar/output.hpp"

namespace oscar {
class PullRequest;
}

namespace oscar::internal {

/// Answers pull requests for one output from its ring buffer. A request for a cue not there yet
/// (PULL_AT_OR_AFTER) is held until the output takes one, up to the request's wait; one whose
/// wait is beyond kMaxPullWait, or beyond kMaxHeldPulls of its requester's, is answered empty
/// at once (the consumer's side refuses both before sending, with the error).
class DdsPullServer final : public eprosima::fastdds::dds::DataReaderListener {
 public:
  /// `output` must outlive the server.
  DdsPullServer(DdsParticipant& participant, OutputPort& output);
  /// Answers the held requests empty.
  ~DdsPullServer() override;
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;
  /// Requests held now, waiting for a cue.
  std::size_t held() const { return held_->held(); }

 private:
  void hold(const PullRequest& request);

  DdsParticipant& participant_;
  OutputPort& output_;
  eprosima::fastdds::dds::DataReader* requests_ = nullptr;
  eprosima::fastdds::dds::DataWriter* replies_ = nullptr;
  // Connected to the output like a push input once a request is held: its arrival hook, on the
  // publishing thread, answers the held requests the new cue matches.
  InputPort watcher_;
  std::once_flag watching_;
  std::unique_ptr<HeldPulls> held_;
};

/// Sends pull requests for one input to a remote output and resolves them from the replies.
class DdsPullSource final : public PullSource, public eprosima::fastdds::dds::DataReaderListener {
 public:
  /// `requester` names the input (unique in the system); each source adds its own number.
  DdsPullSource(DdsParticipant& participant, InputPort& input, const std::string& source,
                const std::string& requester);
  ~DdsPullSource() override;
  /// Waits until the producer's pull server is matched both ways and has answered a pull of no
  /// cues (so that the input's first pull is not lost to discovery still under way).
  bool wait_matched(std::chrono::milliseconds timeout);
  /// @throws std::length_error if kMaxHeldPulls of this source's PULL_AT_OR_AFTER requests
  ///         wait for their answer.
  std::shared_future<std::shared_ptr<const void>> request(PullQuery query, Stamp t,
                                                          std::chrono::nanoseconds wait) override;
  std::shared_future<CueBlock> request(const PullBlock& block) override;
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;
  /// Replies to other consumers that reached this source's reader: none, as the reply filter
  /// keeps them at the producer (a test shows it).
  std::uint64_t others_replies_seen() const { return others_replies_seen_; }

 private:
  using Pending = std::variant<std::promise<std::shared_ptr<const void>>, std::promise<CueBlock>>;
  // `held_for`: how long the producer may hold it (PULL_AT_OR_AFTER).
  void send(PullRequest& request, Pending pending,
            std::chrono::nanoseconds held_for = std::chrono::nanoseconds::zero());
  void make_room_to_hold_locked();  // @throws std::length_error at kMaxHeldPulls

  DdsParticipant& participant_;
  InputPort& input_;
  std::string requester_;
  eprosima::fastdds::dds::DataWriter* requests_ = nullptr;
  eprosima::fastdds::dds::ContentFilteredTopic* my_replies_ = nullptr;
  eprosima::fastdds::dds::DataReader* replies_ = nullptr;
  std::atomic<std::uint64_t> others_replies_seen_{0};
  std::mutex mutex_;
  std::uint64_t next_id_ = 1;
  std::map<std::uint64_t, Pending> pending_;
  // Held requests (PULL_AT_OR_AFTER) not answered yet: by id, until when the producer holds them.
  std::map<std::uint64_t, std::chrono::steady_clock::time_point> held_;
};

}  // namespace oscar::internal
