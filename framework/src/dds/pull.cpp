#include "dds/pull.hpp"

#include <thread>

#include <fmt/format.h>
#include <oscar/pullPubSubTypes.h>

namespace oscar::internal {
namespace dds = eprosima::fastdds::dds;

namespace {
dds::DataWriterQos reliable_writer() {
  dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 16;
  return q;
}
dds::DataReaderQos reliable_reader() {
  dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 16;
  return q;
}
}  // namespace

std::string pull_request_topic(const std::string& address) {
  return "oscar/pull/" + address + "/request";
}
std::string pull_reply_topic(const std::string& address) {
  return "oscar/pull/" + address + "/reply";
}

DdsPullServer::DdsPullServer(DdsParticipant& participant, OutputPort& output)
    : participant_(participant), output_(output) {
  replies_ = participant.publisher().create_datawriter(
      &participant.topic(pull_reply_topic(output.address()), new PullReplyPubSubType()),
      reliable_writer());
  requests_ = participant.subscriber().create_datareader(
      &participant.topic(pull_request_topic(output.address()), new PullRequestPubSubType()),
      reliable_reader(), this, dds::StatusMask::data_available());
  if (!replies_ || !requests_) {
    throw std::runtime_error("cannot create the pull endpoints of " + output.address());
  }
}

DdsPullServer::~DdsPullServer() {
  participant_.subscriber().delete_datareader(requests_);
  participant_.publisher().delete_datawriter(replies_);
}

void DdsPullServer::on_data_available(dds::DataReader* reader) {
  PullRequest request;
  dds::SampleInfo info;
  while (reader->take_next_sample(&request, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    std::optional<RingEntry> e;
    const auto t = static_cast<Stamp>(request.t_ns());
    switch (request.query()) {
      case PULL_LATEST:
        e = output_.buffer().latest();
        break;
      case PULL_AT_OR_BEFORE:
        e = output_.buffer().at_or_before(t);
        break;
      case PULL_NEAREST:
        e = output_.buffer().nearest(t);
        break;
    }
    PullReply reply;
    reply.requester(request.requester());
    reply.id(request.id());
    reply.found(e.has_value());
    if (e) reply.cdr(output_.type().serialize(e->cue.get()));
    replies_->write(&reply);
  }
}

DdsPullSource::DdsPullSource(DdsParticipant& participant, InputPort& input,
                             const std::string& source, std::string requester)
    : participant_(participant), input_(input), requester_(std::move(requester)) {
  requests_ = participant.publisher().create_datawriter(
      &participant.topic(pull_request_topic(source), new PullRequestPubSubType()),
      reliable_writer());
  replies_ = participant.subscriber().create_datareader(
      &participant.topic(pull_reply_topic(source), new PullReplyPubSubType()), reliable_reader(),
      this, dds::StatusMask::data_available());
  if (!replies_ || !requests_)
    throw std::runtime_error("cannot create pull endpoints for " + source);
}

DdsPullSource::~DdsPullSource() {
  participant_.subscriber().delete_datareader(replies_);
  participant_.publisher().delete_datawriter(requests_);
  std::lock_guard lock(mutex_);
  for (auto& [id, promise] : pending_) promise.set_value(nullptr);
}

bool DdsPullSource::wait_matched(std::chrono::milliseconds timeout) const {
  const auto until = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    dds::PublicationMatchedStatus pub;
    dds::SubscriptionMatchedStatus sub;
    requests_->get_publication_matched_status(pub);
    replies_->get_subscription_matched_status(sub);
    if (pub.current_count > 0 && sub.current_count > 0) return true;
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

std::shared_future<std::shared_ptr<const void>> DdsPullSource::request(PullQuery query, Stamp t) {
  PullRequest request;
  request.requester(requester_);
  request.query(query == PullQuery::kLatest       ? PULL_LATEST
                : query == PullQuery::kAtOrBefore ? PULL_AT_OR_BEFORE
                                                  : PULL_NEAREST);
  request.t_ns(static_cast<unsigned long long>(t));
  std::shared_future<std::shared_ptr<const void>> answer;
  {
    std::lock_guard lock(mutex_);
    request.id(next_id_++);
    answer = pending_[request.id()].get_future().share();
  }
  requests_->write(&request);
  return answer;
}

void DdsPullSource::on_data_available(dds::DataReader* reader) {
  PullReply reply;
  dds::SampleInfo info;
  while (reader->take_next_sample(&reply, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || reply.requester() != requester_) continue;
    std::shared_ptr<const void> cue;
    if (reply.found()) {
      try {
        cue = input_.type().deserialize(reply.cdr());
        input_.buffer().push(cue, generation_stamp(input_.type().header(cue.get())), wall_now());
      } catch (const std::exception&) {
        cue = nullptr;  // a malformed reply answers "nothing", never garbage
      }
    }
    std::lock_guard lock(mutex_);
    if (auto it = pending_.find(reply.id()); it != pending_.end()) {
      it->second.set_value(cue);
      pending_.erase(it);
    }
  }
}

}  // namespace oscar::internal
