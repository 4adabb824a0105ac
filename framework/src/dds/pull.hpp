#pragma once
// Pull transfer across processes (docs/kernels.md): a consumer's request reaches the producer's
// frame, which answers from the output's ring buffer with the cues serialized as CDR. Replies to
// all consumers share the output's reply topic; each consumer reads it through a content filter
// on the requester, which the producer's writer evaluates, so a reply travels to its asker only.

#include <atomic>
#include <future>
#include <map>
#include <mutex>
#include <string>
#include <variant>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>

#include "oscar/dds_participant.hpp"
#include "oscar/input.hpp"
#include "oscar/output.hpp"

namespace oscar {
class PullRequest;
}

namespace oscar::internal {

/// Answers pull requests for one output from its ring buffer.
class DdsPullServer final : public eprosima::fastdds::dds::DataReaderListener {
 public:
  DdsPullServer(DdsParticipant& participant, OutputPort& output);
  ~DdsPullServer() override;
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;

 private:
  DdsParticipant& participant_;
  OutputPort& output_;
  eprosima::fastdds::dds::DataReader* requests_ = nullptr;
  eprosima::fastdds::dds::DataWriter* replies_ = nullptr;
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
  std::shared_future<std::shared_ptr<const void>> request(PullQuery query, Stamp t) override;
  std::shared_future<CueBlock> request(const PullBlock& block) override;
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;
  /// Replies to other consumers that reached this source's reader: none, as the reply filter
  /// keeps them at the producer (a test shows it).
  std::uint64_t others_replies_seen() const { return others_replies_seen_; }

 private:
  using Pending = std::variant<std::promise<std::shared_ptr<const void>>, std::promise<CueBlock>>;
  void send(PullRequest& request, Pending pending);

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
};

}  // namespace oscar::internal
