#include "dds/pull.hpp"

#include "dds/wire_bounds.hpp"
#include "oscar/malformed_samples.hpp"
#include "oscar/topics.hpp"

#include <thread>

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fmt/format.h>
#include <oscar/pullPubSubTypes.h>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>

namespace oscar::internal {
namespace dds = eprosima::fastdds::dds;

namespace {
// Data sharing would make the writer leave content filtering to the readers (so would
// intra-process delivery and multicast, which OSCAR's participants do not use across processes).
// The reply filter: a reply passes if its first member, `requester`, is the filter expression.
// Fast DDS's SQL filter would deserialize every reply (cues included) into a dynamic type; this
// one reads one string. Both sides register it: the consumer's participant to create the
// filtered topic, the producer's so its writer evaluates it and sends a reply to its asker only.
constexpr const char* kRequesterFilter = "OSCAR_PULL_REQUESTER";

class RequesterFilter final : public dds::IContentFilter {
 public:
  explicit RequesterFilter(std::string requester) : requester_(std::move(requester)) {}
  bool evaluate(const SerializedPayload& payload, const FilterSampleInfo&,
                const GUID_t&) const override {
    try {
      eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(payload.data), payload.length);
      eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN,
                                 eprosima::fastcdr::Cdr::DDS_CDR);
      cdr.read_encapsulation();
      std::string requester;
      cdr >> requester;
      return requester == requester_;
    } catch (const std::exception&) {
      return false;  // not a PullReply: nobody asked for it
    }
  }

 private:
  std::string requester_;
};

class RequesterFilterFactory final : public dds::IContentFilterFactory {
 public:
  ReturnCode_t create_content_filter(const char*, const char*, const dds::TopicDataType*,
                                     const char* filter_expression, const ParameterSeq&,
                                     dds::IContentFilter*& filter_instance) override {
    if (!filter_expression) {  // new parameters only: it has none
      return filter_instance ? ReturnCode_t::RETCODE_OK : ReturnCode_t::RETCODE_BAD_PARAMETER;
    }
    delete static_cast<RequesterFilter*>(filter_instance);  // only ever one of ours
    filter_instance = new RequesterFilter(filter_expression);
    return ReturnCode_t::RETCODE_OK;
  }
  ReturnCode_t delete_content_filter(const char*, dds::IContentFilter* filter_instance) override {
    delete static_cast<RequesterFilter*>(filter_instance);  // only ever one of ours
    return ReturnCode_t::RETCODE_OK;
  }
};

void register_requester_filter(DdsParticipant& participant) {
  static RequesterFilterFactory factory;  // stateless; outlives every participant
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  auto& p = participant.get();
  if (!p.lookup_content_filter_factory(kRequesterFilter) &&
      p.register_content_filter_factory(kRequesterFilter, &factory) != ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error("cannot register the pull reply filter");
  }
}

std::vector<RingEntry> answer(const RingBuffer& ring, const PullRequest& request) {
  const auto t = static_cast<Stamp>(request.t_ns());
  const auto one = [](std::optional<RingEntry> e) {
    return e ? std::vector<RingEntry>{std::move(*e)} : std::vector<RingEntry>{};
  };
  switch (request.query()) {
    case PULL_LATEST:
      return one(ring.latest());
    case PULL_AT_OR_BEFORE:
      return one(ring.at_or_before(t));
    case PULL_NEAREST:
      return one(ring.nearest(t));
    case PULL_LATEST_N:
      return ring.latest(static_cast<std::size_t>(request.n()));
    case PULL_RANGE: {
      const auto t1 = static_cast<Stamp>(request.t1_ns());
      return t <= t1 ? ring.range(t, t1) : std::vector<RingEntry>{};  // inverted: nothing
    }
    case PULL_AT_OR_AFTER:
      return one(first_at_or_after(ring, t));  // a request with no wait (held ones: hold())
  }
  return {};  // a kind this version does not know
}
}  // namespace

DdsPullServer::DdsPullServer(DdsParticipant& participant, OutputPort& output)
    : participant_(participant),
      output_(output),
      watcher_(output.kernel(), output.name() + " (held pulls)", output.type(),
               InputOptions{.depth = 1}),
      held_(std::make_unique<HeldPulls>(output.buffer())) {
  register_requester_filter(participant);  // before the writer meets a filtered reader
  const auto replies = topics::pull_reply(output.address());
  const auto requests = topics::pull_request(output.address());
  replies_ = participant.publisher().create_datawriter(
      &participant.topic(replies.name, new PullReplyPubSubType()), replies.writer_qos);
  requests_ = participant.subscriber().create_datareader(
      &participant.topic(requests.name, new PullRequestPubSubType()), requests.reader_qos, this,
      dds::StatusMask::data_available());
  if (!replies_ || !requests_) {
    throw std::runtime_error("cannot create the pull endpoints of " + output.address());
  }
}

DdsPullServer::~DdsPullServer() {
  participant_.subscriber().delete_datareader(requests_);  // no new requests
  output_.disconnect(&watcher_);                           // no new answers from the output
  const bool answered = held_->held() > 0;
  held_.reset();  // answers what is held: empty, while the reply writer is still there
  // A writer deleted at once drops what its readers have not acknowledged: those answers would
  // be lost, and their consumers would wait out their whole wait.
  if (answered) replies_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(0, 500'000'000));
  participant_.publisher().delete_datawriter(replies_);
}

void DdsPullServer::hold(const PullRequest& request) {
  auto answer = [this, requester = request.requester(),
                 id = request.id()](std::optional<RingEntry> e) {
    PullReply reply;
    reply.requester(requester);
    reply.id(id);
    if (e) reply.cues().emplace_back().cdr(output_.type().serialize(e->cue.get()));
    replies_->write(&reply);
  };
  const auto wait = std::chrono::nanoseconds(request.wait_ns());
  if (wait > kMaxPullWait) return answer(std::nullopt);  // the consumer's side refuses it first
  std::call_once(watching_, [this] {
    watcher_.set_arrival_hook([this] {
      if (auto e = watcher_.buffer().latest()) held_->arrived(*e);
    });
    output_.connect(&watcher_);
  });
  try {
    held_->ask(request.requester(), static_cast<Stamp>(request.t_ns()), wait, answer);
  } catch (const std::length_error&) {
    answer(std::nullopt);  // beyond its requester's limit (the consumer's side refuses it first)
  }
}

void DdsPullServer::on_data_available(dds::DataReader* reader) {
  PullRequest request;
  dds::SampleInfo info;
  while (take_next(*reader, &request, info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    if (request.query() == PULL_AT_OR_AFTER && request.wait_ns() > 0) {
      hold(request);
      continue;
    }
    PullReply reply;
    reply.requester(request.requester());
    reply.id(request.id());
    for (const auto& e : answer(output_.buffer(), request)) {
      reply.cues().emplace_back().cdr(output_.type().serialize(e.cue.get()));
    }
    replies_->write(&reply);
  }
}

DdsPullSource::DdsPullSource(DdsParticipant& participant, InputPort& input,
                             const std::string& source, const std::string& requester)
    : participant_(participant), input_(input) {
  // A rewire makes the new source before it drops the old one, possibly to the same producer:
  // each source has a name of its own, for its filtered topic and its replies.
  static std::atomic<std::uint64_t> sources{0};
  requester_ = fmt::format("{}#{}", requester, ++sources);
  register_requester_filter(participant);
  const auto requests = topics::pull_request(source);
  const auto replies = topics::pull_reply(source);
  requests_ = participant.publisher().create_datawriter(
      &participant.topic(requests.name, new PullRequestPubSubType()), requests.writer_qos);
  my_replies_ = participant.get().create_contentfilteredtopic(
      replies.name + "/" + requester_, &participant.topic(replies.name, new PullReplyPubSubType()),
      requester_, {}, kRequesterFilter);
  if (my_replies_) {
    replies_ = participant.subscriber().create_datareader(my_replies_, replies.reader_qos, this,
                                                          dds::StatusMask::data_available());
  }
  if (!replies_ || !requests_) {
    if (requests_) participant.publisher().delete_datawriter(requests_);
    if (my_replies_) participant.get().delete_contentfilteredtopic(my_replies_);
    throw std::runtime_error("cannot create pull endpoints for " + source);
  }
}

DdsPullSource::~DdsPullSource() {
  participant_.subscriber().delete_datareader(replies_);
  participant_.get().delete_contentfilteredtopic(my_replies_);
  participant_.publisher().delete_datawriter(requests_);
  std::lock_guard lock(mutex_);
  for (auto& [id, pending] : pending_) {
    if (auto* one = std::get_if<std::promise<std::shared_ptr<const void>>>(&pending)) {
      one->set_value(nullptr);
    } else {
      std::get<std::promise<CueBlock>>(pending).set_value(CueBlock{});
    }
  }
}

bool DdsPullSource::wait_matched(std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    dds::PublicationMatchedStatus pub;
    dds::SubscriptionMatchedStatus sub;
    requests_->get_publication_matched_status(pub);
    replies_->get_subscription_matched_status(sub);
    if (pub.current_count > 0 && sub.current_count > 0) break;
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  // Our reader knowing the producer's reply writer does not mean that writer knows our reader
  // (discovery is not symmetric in time): a reply it sends before would be lost, and the input's
  // first pull with it. A pull of no cues, answered, shows the way back is open.
  for (;;) {
    const auto probe = request(PullBlock::latest(0));
    const auto left = until - std::chrono::steady_clock::now();
    const auto wait =
        std::min<std::chrono::steady_clock::duration>(left, std::chrono::milliseconds(50));
    if (wait > std::chrono::steady_clock::duration::zero() &&
        probe.wait_for(wait) == std::future_status::ready) {
      return true;
    }
    if (std::chrono::steady_clock::now() > until) return false;
  }
}

void DdsPullSource::send(PullRequest& request, Pending pending, std::chrono::nanoseconds held_for) {
  request.requester(requester_);
  {
    std::lock_guard lock(mutex_);
    const bool held = held_for > std::chrono::nanoseconds::zero();
    if (held) make_room_to_hold_locked();
    request.id(next_id_++);
    if (held) held_.emplace(request.id(), std::chrono::steady_clock::now() + held_for);
    pending_.emplace(request.id(), std::move(pending));
  }
  requests_->write(&request);
}

void DdsPullSource::make_room_to_hold_locked() {
  // A producer that went away answers nothing: a held request unanswered well after its wait
  // ended is answered empty here, so it neither blocks its asker nor counts against the limit.
  const auto now = std::chrono::steady_clock::now();
  for (auto it = held_.begin(); it != held_.end();) {
    if (it->second + std::chrono::seconds(1) < now) {
      if (auto p = pending_.find(it->first); p != pending_.end()) {
        std::get<std::promise<std::shared_ptr<const void>>>(p->second).set_value(nullptr);
        pending_.erase(p);
      }
      it = held_.erase(it);
    } else {
      ++it;
    }
  }
  if (held_.size() >= kMaxHeldPulls) {
    throw std::length_error(
        fmt::format("pull of {} refused: {} of its pulls wait for a cue already, and a producer "
                    "holds at most {} per input",
                    requester_, held_.size(), kMaxHeldPulls));
  }
}

std::shared_future<std::shared_ptr<const void>> DdsPullSource::request(
    PullQuery query, Stamp t, std::chrono::nanoseconds wait) {
  PullRequest request;
  switch (query) {
    case PullQuery::kLatest:
      request.query(PULL_LATEST);
      break;
    case PullQuery::kAtOrBefore:
      request.query(PULL_AT_OR_BEFORE);
      break;
    case PullQuery::kNearest:
      request.query(PULL_NEAREST);
      break;
    case PullQuery::kAtOrAfter:
      request.query(PULL_AT_OR_AFTER);
      request.wait_ns(static_cast<unsigned long long>(std::max(wait.count(), std::int64_t{0})));
      break;
  }
  request.t_ns(static_cast<unsigned long long>(t));
  std::promise<std::shared_ptr<const void>> promise;
  auto answer = promise.get_future().share();
  send(request, std::move(promise),
       query == PullQuery::kAtOrAfter ? wait : std::chrono::nanoseconds::zero());
  return answer;
}

std::shared_future<CueBlock> DdsPullSource::request(const PullBlock& block) {
  PullRequest request;
  if (block.kind == PullBlock::Kind::kLatest) {
    request.query(PULL_LATEST_N);
    request.n(block.n);
  } else {
    request.query(PULL_RANGE);
    request.t_ns(static_cast<unsigned long long>(block.t0));
    request.t1_ns(static_cast<unsigned long long>(block.t1));
  }
  std::promise<CueBlock> promise;
  auto answer = promise.get_future().share();
  send(request, std::move(promise));
  return answer;
}

void DdsPullSource::on_data_available(dds::DataReader* reader) {
  PullReply reply;
  dds::SampleInfo info;
  while (take_next(*reader, &reply, info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    if (reply.requester() != requester_) {  // the filter lets none through; be sure
      ++others_replies_seen_;
      continue;
    }
    CueBlock cues;
    try {
      // The cues inside a reply get the size checks a cue's own reader makes before decoding.
      const auto check = wire_check(input_.type().name);
      for (const auto& c : reply.cues()) {
        if (const auto why = check ? check(c.cdr()) : std::nullopt) throw std::runtime_error(*why);
        cues.push_back(input_.type().deserialize(c.cdr()));
      }
    } catch (const std::exception& e) {
      note_malformed_sample(input_.type().name, e.what());
      cues.clear();  // a malformed reply answers "nothing", never garbage
    }
    for (const auto& cue : cues) {
      input_.buffer().push(cue, input_.type().header.generation_stamp(cue.get()), wall_now());
    }
    std::lock_guard lock(mutex_);
    held_.erase(reply.id());
    if (auto it = pending_.find(reply.id()); it != pending_.end()) {
      if (auto* one = std::get_if<std::promise<std::shared_ptr<const void>>>(&it->second)) {
        one->set_value(cues.empty() ? nullptr : cues.front());
      } else {
        std::get<std::promise<CueBlock>>(it->second).set_value(std::move(cues));
      }
      pending_.erase(it);
    }
  }
}

}  // namespace oscar::internal
