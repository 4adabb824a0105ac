#pragma once
// Pull transfer across processes (docs/kernels.md): a consumer's request reaches the producer's
// frame, which answers from the output's ring buffer with the cue serialized as CDR.

#include <atomic>
#include <future>
#include <map>
#include <mutex>
#include <string>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>

#include "oscar/dds_participant.hpp"
#include "oscar/input.hpp"
#include "oscar/output.hpp"

namespace oscar::internal {

std::string pull_request_topic(const std::string& address);
std::string pull_reply_topic(const std::string& address);

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
  DdsPullSource(DdsParticipant& participant, InputPort& input, const std::string& source,
                std::string requester);
  ~DdsPullSource() override;
  /// Waits until the producer's pull server is matched both ways.
  bool wait_matched(std::chrono::milliseconds timeout) const;
  std::shared_future<std::shared_ptr<const void>> request(PullQuery query, Stamp t) override;
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;

 private:
  DdsParticipant& participant_;
  InputPort& input_;
  std::string requester_;
  eprosima::fastdds::dds::DataWriter* requests_ = nullptr;
  eprosima::fastdds::dds::DataReader* replies_ = nullptr;
  std::mutex mutex_;
  std::uint64_t next_id_ = 1;
  std::map<std::uint64_t, std::promise<std::shared_ptr<const void>>> pending_;
};

}  // namespace oscar::internal
