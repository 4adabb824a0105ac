#include "dds/module_dds.hpp"

#include "command_bounds.hpp"
#include "dds/guarded_type.hpp"
#include "dds/log_sink.hpp"
#include "oscar/malformed_samples.hpp"
#include "oscar/raw_cdr_type.hpp"
#include "oscar/security_files.hpp"
#include "oscar/shared_memory.hpp"
#include "oscar/topic_io.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <fmt/ostream.h>
#include <oscar/configPubSubTypes.h>
#include <oscar/registryPubSubTypes.h>

#if OSCAR_ZERO_COPY
#include "zero_copy/chunk_feed.hpp"
#include "zero_copy/chunk_publisher.hpp"
#include "zero_copy/chunk_pull_source.hpp"
#include "zero_copy/cue_path.hpp"
#include "zero_copy/output_chunks.hpp"
#include "zero_copy/roudi.hpp"
#endif

namespace oscar {
namespace dds = eprosima::fastdds::dds;

// Writes an output's cues to DDS, skipping the serialisation while nobody listens (volatile).
class Module::Dds::OutputWriter final : public dds::DataWriterListener {
 public:
  OutputWriter(DdsParticipant& p, OutputPort& out) : out_(out) {
    auto& topic = p.topic(topics::cue(out.address()), out.type().new_topic_type());
    writer_ = p.publisher().create_datawriter(&topic, qos::cue_writer(out.options()), this,
                                              dds::StatusMask::publication_matched());
    if (!writer_) {
      throw std::runtime_error("cannot create a writer for " + out.address() +
                               p.permission_hint(topics::cue(out.address())));
    }
    const bool keep_history = out.options().transient_local;
    out.set_remote([this, keep_history](const void* cue) {
      if (keep_history || matched_.load(std::memory_order_relaxed) > 0) {
        writer_->write(const_cast<void*>(cue));
      }
    });
  }
  ~OutputWriter() override { out_.set_remote(nullptr); }
  void on_publication_matched(dds::DataWriter*,
                              const dds::PublicationMatchedStatus& status) override {
    matched_ = status.current_count;
  }
  dds::DataWriter* writer_ = nullptr;

 private:
  OutputPort& out_;
  std::atomic<int> matched_{0};
};

namespace {
// What a reader of `type` takes from DDS for `input`: the input's own type; for a raw input the
// type's support if this process knows the type (each cue is then serialized for the input), or
// nullptr: RawCdrType keeps the bytes. A type the process knows is read with its support, so
// that a topic of it here never gets RawCdrType and a typed port here the other way round.
const CueTypeInfo* wire_type(DdsParticipant& p, const InputPort& input, const std::string& type) {
  if (!input.takes_any_type()) return &input.type();
  const auto registered = p.get().find_type(type);
  const auto* guarded = dynamic_cast<internal::GuardedType*>(registered.get());
  if (guarded && dynamic_cast<const RawCdrType*>(&guarded->inner())) return nullptr;
  return find_cue_type(type);
}
}  // namespace

class Module::Dds::CueReader final : public dds::DataReaderListener {
 public:
  /// `producer`: the source output's declared options, as far as they are known; `type`: the
  /// producer's type name; `replaces`: the input's reader so far, which delivers nothing more
  /// once this one has delivered its first cue (a rewire switches at one point of the stream).
  CueReader(Dds& owner, InputPort& input, const std::string& source, const OutputOptions& producer,
            const std::string& type, CueReader* replaces)
      : owner_(owner),
        input_(input),
        source_(source),
        type_(type),
        producer_(producer),
        wire_(wire_type(owner.participant_, input, type)),
        replaces_(replaces) {
    auto& p = owner.participant_;
    auto& topic =
        p.topic(topics::cue(source), wire_ ? wire_->new_topic_type() : new RawCdrType(type));
    reader_ = p.subscriber().create_datareader(
        &topic, qos::cue_reader(producer, input.buffer().depth(), input.reliability()), this,
        dds::StatusMask::data_available() << dds::StatusMask::subscription_matched()
                                          << dds::StatusMask::requested_incompatible_qos());
    if (!reader_) throw std::runtime_error("cannot create a reader for " + source);
  }
  const std::string& source() const { return source_; }
  const std::string& type() const { return type_; }
  void on_data_available(dds::DataReader* reader) override {
    const auto& arriving = wire_ ? *wire_ : raw_cue_type();
    dds::SampleInfo info;
    for (;;) {
      auto cue = arriving.make();
      if (take_next(*reader, cue.get(), info) != ReturnCode_t::RETCODE_OK) break;
      if (!info.valid_data) continue;
      if (!received_) take_over();
      std::lock_guard lock(deliver_mutex_);
      if (retired_) continue;
      input_.deliver_from(arriving, std::move(cue));
      received_ = true;
    }
  }
  /// Delivers nothing from now on; returns once a delivery under way is done.
  void retire() {
    std::lock_guard lock(deliver_mutex_);
    retired_ = true;
  }
  /// The reader this one replaced is deleted: nothing to retire any more.
  void forget_replaced() {
    std::lock_guard lock(replaces_mutex_);
    replaces_ = nullptr;
  }
  void on_subscription_matched(dds::DataReader*,
                               const dds::SubscriptionMatchedStatus& status) override {
    matched_ = status.current_count;
  }
  // A writer that offers less than this reader asks: the producer was not seen when the reader
  // was made, and is best effort (or volatile). The frame makes one that asks no more than that.
  void on_requested_incompatible_qos(dds::DataReader*,
                                     const dds::RequestedIncompatibleQosStatus& status) override {
    auto offered = producer_;
    if (status.last_policy_id == dds::RELIABILITY_QOS_POLICY_ID) {
      offered.reliable = false;
    } else if (status.last_policy_id == dds::DURABILITY_QOS_POLICY_ID) {
      offered.transient_local = false;
    } else {
      return;  // nothing a cue reader's QoS could give
    }
    owner_.follow_producer(input_, source_, offered);
  }
  bool wait_matched(std::chrono::steady_clock::time_point until) const {
    while (matched_.load() == 0 && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return matched_.load() > 0;
  }
  /// Waits up to `timeout` for the first cue: once one came, the producer's writer has matched
  /// this reader too, so every cue it publishes from then on arrives.
  bool wait_first_cue(std::chrono::milliseconds timeout) const {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (!received_.load() && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return received_.load();
  }
  bool received() const { return received_.load(); }
  dds::DataReader* reader_ = nullptr;

 private:
  std::atomic<bool> received_{false};
  Dds& owner_;
  InputPort& input_;
  std::string source_, type_;
  OutputOptions producer_;
  const CueTypeInfo* wire_;  // what the reader takes; nullptr: RawCue from RawCdrType
  std::atomic<int> matched_{0};
  std::mutex deliver_mutex_;  // a delivery, against retire()
  bool retired_ = false;
  std::mutex replaces_mutex_;
  CueReader* replaces_;

  void take_over() {
    std::lock_guard lock(replaces_mutex_);
    if (replaces_) replaces_->retire();
    replaces_ = nullptr;
  }
};

// Only the topics it shares, unless an input takes any type: such an input is subscribed once
// discovery shows a writer of its source, which a plain client learns of only through a reader
// of the topic, and that needs the type.
DiscoveryScope Module::Dds::discovery_scope_of(const Module& module) {
  for (const auto& s : module.slots_) {
    for (const auto& input : s->instance->ports().inputs) {
      if (input->takes_any_type()) return DiscoveryScope::kWholeSystem;
    }
  }
  return DiscoveryScope::kSharedTopics;
}

// A module without outputs sends no cues: a small shared-memory segment holds what it sends.
NetworkConfig Module::Dds::network_of(const Module& module) {
  auto network = module.spec_.network;
  const bool publishes_cues = std::any_of(module.slots_.begin(), module.slots_.end(), [](auto& s) {
    return !s->instance->ports().outputs.empty();
  });
  network.shm_segment_bytes = shm_segment_bytes_for(network, publishes_cues);
  return network;
}

Module::Dds::Dds(Module& module, int domain)
    : module_(module),
      domain_(domain),
      discovery_scope_(discovery_scope_of(module)),
      participant_(domain, "oscar:" + module.spec_.name, network_of(module), discovery_scope_),
      learns_only_shared_topics_(module.spec_.network.discovery == Discovery::kServer &&
                                 discovery_scope_ == DiscoveryScope::kSharedTopics) {
  // Samples dropped as malformed are reported where the module's other lines go: its console
  // and oscar/log. The logger outlives this (shared), and its DDS sink is detached below.
  set_malformed_sample_log(module.log_);
  if (const auto& security = module.spec_.network.security) {
    trusted_writers_.emplace(
        security->keystore,
        std::vector<std::string>{security_files::module_identity("coordinator"),
                                 security_files::kRegistry, security_files::kBoot,
                                 security_files::kOperatorBoot});
    for (const auto& identity : trusted_writers_->missing()) {
      module.log_->warn(
          "keystore {} holds no certificate of identity '{}': its configuration "
          "commands will be refused (oscar security init adds it)",
          security->keystore, identity);
    }
  }
  join_zero_copy();
}

Module::Dds::~Dds() {
  roudi_watch_.reset();  // it may end the module, which logs through what follows
  std::map<InputPort*, std::shared_ptr<void>> feeds;
  {
    std::lock_guard lock(readers_mutex_);
    feeds.swap(feeds_);
  }
  feeds.clear();  // their threads deliver nothing more
  for (auto* out : chunked_outputs_) out->set_chunks(nullptr);
  wishes_.reset();
  module_.log_sink_->attach(nullptr);
  stop_config();
  {
    std::lock_guard lock(readers_mutex_);
    for (auto& [input, reader] : readers_)
      participant_.subscriber().delete_datareader(reader->reader_);
    readers_.clear();
  }
  for (auto& [input, pulls] : pull_sources_) input->set_pull_source(nullptr);
  pull_sources_.clear();
  pull_servers_.clear();
  for (auto& w : writers_) participant_.publisher().delete_datawriter(w->writer_);
  writers_.clear();
}

void Module::Dds::wire_wishes(std::vector<std::unique_ptr<Slot>>& slots) {
  std::vector<internal::ModuleWishes::Entry> entries;
  for (auto& s : slots) {
    for (auto& w : s->instance->ports().wishes) entries.push_back({w.get(), &s->active});
  }
  if (entries.empty()) return;
  wishes_ = std::make_unique<internal::ModuleWishes>(participant_, module_.spec_.name,
                                                     module_.spec_.incarnation, std::move(entries));
}

void Module::Dds::wire_outputs(std::vector<std::unique_ptr<Slot>>& slots) {
  for (auto& s : slots) {
    for (auto& out : s->instance->ports().outputs) {
      offer_chunks(*out);  // before its writer: a consumer that discovers it finds them offered
      writers_.push_back(std::make_unique<OutputWriter>(participant_, *out));
      pull_servers_.push_back(std::make_unique<internal::DdsPullServer>(participant_, *out));
    }
  }
}

bool Module::Dds::offer_chunks(OutputPort& out) {
#if OSCAR_ZERO_COPY
  if (!zero_copy_ || !out.type().memory.plain) return false;
  try {
    // The publisher keeps what the ring holds (up to iceoryx's 16) for pulls that start later.
    out.set_chunks(std::make_shared<zero_copy::OutputChunks>(
        zero_copy::zero_copy_topic(domain_, topics::cue(out.address())), out.type(),
        std::min(out.options().depth, zero_copy::kMaxChunkHistory)));
    chunked_outputs_.push_back(&out);
    return true;
  } catch (const std::exception& e) {
    module_.log_->warn("output {}: its cues go through DDS only: {}", out.address(), e.what());
  }
#endif
  return false;
}

void Module::Dds::join_zero_copy() {
#if OSCAR_ZERO_COPY
  bool plain = false;
  for (const auto& s : module_.slots_) {
    const auto& ports = s->instance->ports();
    for (const auto& out : ports.outputs) plain = plain || out->type().memory.plain;
    for (const auto& in : ports.inputs) {
      plain = plain || (!in->takes_any_type() && in->type().memory.plain);
    }
  }
  if (!plain) return;
  if (const auto why = join_roudi()) {
    module_.log_->info("its plain cues go through DDS only: {}{}", *why,
                       roudi_later_ ? "; it joins RouDi once one runs" : "");
  }
#endif
}

std::optional<std::string> Module::Dds::join_roudi() {
#if OSCAR_ZERO_COPY
  try {
    // iceoryx would abort the module (in a port request a RouDi killed meanwhile leaves
    // unanswered).
    zero_copy::end_process_on_iceoryx_error(
        kKernelFailureExit, [log = module_.log_](const std::string& what, bool ending) {
          if (!ending) return log->warn("{}", what);
          log->error("{}; the registry starts it again on the host's RouDi", what);
          log->flush();
        });
    // A runtime name of its own per process: a restarted module must not look like the old one.
    if (auto why = zero_copy::join_roudi(fmt::format("{}-{}", module_.spec_.name, getpid()))) {
      roudi_later_ = true;
      return why;
    }
    zero_copy_ = true;
    roudi_watch_ = std::make_shared<zero_copy::RoudiWatch>([this](const std::string& why) {
      module_.end_for_restart(why + "; the registry starts it again on the host's RouDi");
    });
    return std::nullopt;
  } catch (const std::exception& e) {
    return e.what();
  }
#else
  return "this build has no zero-copy path";
#endif
}

// On the configuration thread, every second while roudi_later_.
void Module::Dds::join_roudi_later() {
#if OSCAR_ZERO_COPY
  if (!zero_copy::roudi_running()) return;
  roudi_later_ = false;
  if (const auto why = join_roudi()) {
    module_.log_->warn("its plain cues stay on DDS: {}", *why);
    return;
  }
  std::size_t outputs = 0;
  for (const auto& s : module_.slots_) {
    for (const auto& out : s->instance->ports().outputs) outputs += offer_chunks(*out) ? 1 : 0;
  }
  std::map<InputPort*, std::string> on_dds;  // plain push inputs: switch_to_offered() takes them
  {
    std::lock_guard lock(readers_mutex_);
    for (const auto& [input, reader] : readers_) {
      if (!input->takes_any_type() && input->type().memory.plain) on_dds[input] = reader->source();
    }
    for (const auto& [input, pulls] : pull_sources_) {
      if (!input->takes_any_type() && input->type().memory.plain) on_dds[input] = pulls.from;
    }
  }
  {
    std::lock_guard lock(queue_mutex_);
    for (const auto& [input, source] : on_dds)
      awaiting_offer_.try_emplace(input, AwaitingOffer{source});
  }
  module_.log_->info(
      "joined this host's RouDi, which runs now: {} plain output(s) offered in shared memory from "
      "here on, {} plain input(s) go zero-copy once their producers offer",
      outputs, on_dds.size());
#endif
}

#if OSCAR_ZERO_COPY
bool Module::Dds::chunks_offered(InputPort& input, const std::string& source,
                                 std::chrono::steady_clock::time_point until) {
  const auto topic = zero_copy::zero_copy_topic(domain_, topics::cue(source));
  bool offered = false;
  if (input.type().memory.plain) {
    std::optional<std::chrono::steady_clock::time_point> writer_seen;
    while (!(offered = zero_copy::offered_on_this_host(topic, input.type().name))) {
      const auto now = std::chrono::steady_clock::now();
      if (!writer_seen && participant_.discovered_writer(topics::cue(source))) writer_seen = now;
      // An output offers its chunks before it makes its writer; RouDi lists them within its next
      // discovery round.
      if (now >= until && !(writer_seen && now < *writer_seen + std::chrono::milliseconds(300)))
        break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  const auto facts = zero_copy::connection_facts(source, input.type(), offered);
  // Logs why, for a serialized path.
  if (zero_copy::choose_cue_path(facts).path == zero_copy::CuePath::kZeroCopy) return true;
  if (facts.type_is_plain && !facts.producer_on_this_host) {
    std::lock_guard lock(queue_mutex_);
    awaiting_offer_[&input] = {.source = source};  // a producer started later may offer it
  }
  return false;
}
#endif

std::optional<std::string> Module::Dds::feed_zero_copy(InputPort& input, const std::string& source,
                                                       bool producer_seen) {
#if OSCAR_ZERO_COPY
  if (!zero_copy_ || input.takes_any_type()) return std::nullopt;
  const auto topic = zero_copy::zero_copy_topic(domain_, topics::cue(source));
  std::shared_ptr<zero_copy::ChunkFeed> feed;
  try {
    // Its producer's writer was looked for already (a plain client of discovery servers may
    // know it only from asking them): RouDi's next discovery round if it was seen.
    const auto until =
        std::chrono::steady_clock::now() +
        (producer_seen ? std::chrono::milliseconds(300) : std::chrono::milliseconds(0));
    if (!chunks_offered(input, source, until)) return std::nullopt;
    feed = std::make_shared<zero_copy::ChunkFeed>(topic, input, input.type());
  } catch (const std::exception& e) {
    module_.log_->warn("input {}/{}: its cues go through DDS: {}", input.kernel(), input.name(),
                       e.what());
    return std::nullopt;
  }
  disconnect_input(input);  // what fed it before
  {
    std::lock_guard lock(readers_mutex_);
    feeds_[&input] = std::move(feed);
  }
  module_.log_->info("input {}/{}: cues of {} come zero-copy (read in place in shared memory)",
                     input.kernel(), input.name(), source);
  return std::string();
#else
  (void)input;
  (void)source;
  (void)producer_seen;
  return std::nullopt;
#endif
}

std::optional<std::string> Module::Dds::pull_zero_copy(
    InputPort& input, const std::string& source, std::chrono::steady_clock::time_point until) {
#if OSCAR_ZERO_COPY
  if (!zero_copy_ || input.takes_any_type()) return std::nullopt;
  const auto topic = zero_copy::zero_copy_topic(domain_, topics::cue(source));
  std::shared_ptr<zero_copy::ChunkPullSource> puller;
  try {
    if (!chunks_offered(input, source, until)) return std::nullopt;
    puller = std::make_shared<zero_copy::ChunkPullSource>(topic, source, input);
    // A pull before RouDi connected the mirror would find it empty.
    const auto connected = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    while (!puller->subscribed() && std::chrono::steady_clock::now() < connected) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  } catch (const std::exception& e) {
    module_.log_->warn("input {}/{}: its pulls go to the producer over DDS: {}", input.kernel(),
                       input.name(), e.what());
    return std::nullopt;
  }
  input.set_pull_source(puller);  // make, then break: the old source goes with its last user
  {
    std::lock_guard lock(readers_mutex_);
    pull_sources_[&input] = {std::move(puller), source};
  }
  module_.log_->info(
      "input {}/{}: pulls of {} are answered in this process from its chunks in shared memory "
      "(zero-copy)",
      input.kernel(), input.name(), source);
  return std::string();
#else
  (void)input;
  (void)source;
  (void)until;
  return std::nullopt;
#endif
}

std::string Module::Dds::connect_input(InputPort& input, const std::string& source,
                                       std::optional<std::chrono::milliseconds> switch_wait) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(2000);

  if (input.transfer() != Transfer::kPush) {
    if (auto pulled = pull_zero_copy(input, source, until)) return *pulled;
    auto puller = std::make_shared<internal::DdsPullSource>(
        participant_, input, source,
        fmt::format("{}/{}/{}@{}", module_.spec_.name, input.kernel(), input.name(), getpid()));
    std::string note;
    if (!puller->wait_matched(std::chrono::milliseconds(2000))) {
      note = fmt::format("input {}/{}: the producer {} does not answer pulls yet", input.kernel(),
                         input.name(), source);
      module_.log_->warn("{}", note);
    }
    input.set_pull_source(puller);  // make, then break: the old source goes with its last user
    std::lock_guard lock(readers_mutex_);
    pull_sources_[&input] = {std::move(puller), source};
    return note;
  }
  // The reader follows the class the producer declared, which its writer offers: discovery shows
  // it, usually within milliseconds. A producer not seen within the bound gets a reliable,
  // volatile reader, which every reliable writer matches; a best-effort one makes the reader
  // report an incompatible writer, and follow_producer() replaces it. A plain client of the
  // discovery servers learns of the writer only once it reads the topic.
  std::optional<DdsParticipant::DiscoveredWriter> seen;
  if (learns_only_shared_topics_) {
    seen = ask_servers_for_producer(input, source, until);
  } else {
    while (!(seen = participant_.discovered_writer(topics::cue(source))) &&
           std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  // A producer on this host whose writer discovery shows has its chunks offered too (its outputs
  // get their chunks before their writers).
  if (auto fed = feed_zero_copy(input, source, seen.has_value())) return *fed;
  OutputOptions producer;
  if (seen) {
    producer.reliable = seen->reliable;
    producer.transient_local = seen->transient_local;
  } else if (input.takes_any_type()) {
    // No type to read yet: the old source is dropped now (a rewire must not keep reading it),
    // the new one is subscribed by the configuration thread once discovery shows its writer.
    disconnect_input(input);
    {
      std::lock_guard lock(queue_mutex_);
      awaiting_type_[&input] = source;
      queue_cv_.notify_all();
    }
    auto note = fmt::format(
        "input {}/{}: no publisher of {} seen yet, so its type is unknown; it is subscribed once "
        "discovery finds one",
        input.kernel(), input.name(), topics::cue(source));
    module_.log_->warn("{}", note);
    return note;
  }
  return subscribe(input, source, producer, seen ? seen->type : input.type().name, switch_wait,
                   until);
}

std::optional<DdsParticipant::DiscoveredWriter> Module::Dds::ask_servers_for_producer(
    InputPort& input, const std::string& source, std::chrono::steady_clock::time_point until) {
  const auto name = topics::cue(source);
  if (auto seen = participant_.discovered_writer(name)) return seen;  // e.g. another input's
  auto& topic = participant_.topic(name, input.type().new_topic_type());
  // The servers tell a plain client of the writers of a topic it reads, whatever their QoS. The
  // probe matches none of them (exclusive ownership; every OSCAR writer is shared), so it only
  // asks: no writer sends it a cue.
  auto probe_qos = qos::cue_reader({.depth = 1, .reliable = false, .transient_local = false}, 1,
                                   Reliability::kBestEffort);
  probe_qos.ownership().kind = dds::EXCLUSIVE_OWNERSHIP_QOS;
  const auto probe = participant_.subscriber().create_datareader(&topic, probe_qos);
  if (!probe) throw std::runtime_error("cannot create a reader for " + source);
  std::optional<DdsParticipant::DiscoveredWriter> seen;
  while (!(seen = participant_.discovered_writer(name)) &&
         std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  participant_.subscriber().delete_datareader(probe);
  return seen;
}

std::string Module::Dds::subscribe(InputPort& input, const std::string& source,
                                   const OutputOptions& producer, const std::string& type,
                                   std::optional<std::chrono::milliseconds> switch_wait,
                                   std::chrono::steady_clock::time_point until) {
  check_reliability(input, source, producer);
  {
    std::lock_guard lock(queue_mutex_);
    awaiting_type_.erase(&input);  // subscribed now
  }
  CueReader* current = nullptr;  // subscribe() runs on the configuration thread only
  {
    std::lock_guard lock(readers_mutex_);
    if (const auto it = readers_.find(&input); it != readers_.end()) current = it->second.get();
  }
  auto reader = std::make_unique<CueReader>(*this, input, source, producer, type, current);
  auto& fresh = *reader;
  std::string note;
  if (!reader->wait_matched(until)) {
    note = fmt::format("input {}/{}: no publisher of {} matched yet; cues arrive once it appears",
                       input.kernel(), input.name(), topics::cue(source));
    module_.log_->warn("{}", note);
  } else if (switch_wait && !reader->wait_first_cue(*switch_wait)) {
    // Matching is seen by each side on its own: until the producer's writer has matched this
    // reader too, what it publishes does not come here. Its first cue shows it has.
    note = fmt::format(
        "input {}/{}: {} sent no cue within {} ms of the match; switched without it, so a cue it "
        "published just before the switch may be missing",
        input.kernel(), input.name(), source, switch_wait->count());
    module_.log_->warn("{}", note);
  }
  std::unique_ptr<CueReader> old;
  std::shared_ptr<void> old_feed;  // a zero-copy feed from the source before, stopped below
  {
    std::lock_guard lock(readers_mutex_);
    auto& slot = readers_[&input];
    old = std::move(slot);
    slot = std::move(reader);
    if (auto it = feeds_.find(&input); it != feeds_.end()) {
      old_feed = std::move(it->second);
      feeds_.erase(it);
    }
  }
  if (old) {
    old->retire();
    fresh.forget_replaced();
    participant_.subscriber().delete_datareader(old->reader_);
  }
  return note;
}

// On a DDS thread: entities are made on the configuration thread, in order with rewiring.
void Module::Dds::follow_producer(InputPort& input, const std::string& source,
                                  const OutputOptions& offered) {
  std::lock_guard lock(queue_mutex_);
  refollow_.push_back({&input, source, offered});
  queue_cv_.notify_all();
}

void Module::Dds::refollow(const Refollow& r) {
  std::string type;
  {
    std::lock_guard lock(readers_mutex_);
    const auto it = readers_.find(r.input);
    if (it == readers_.end() || it->second->source() != r.source) return;  // rewired since
    type = it->second->type();
  }
  try {
    subscribe(*r.input, r.source, r.offered, type, std::nullopt,
              std::chrono::steady_clock::now() + std::chrono::milliseconds(2000));
  } catch (const std::exception& e) {
    module_.log_->error("{}", e.what());
  }
}

// On the configuration thread: raw inputs whose source discovery has found since.
void Module::Dds::subscribe_discovered() {
  std::map<InputPort*, std::string> awaiting;
  {
    std::lock_guard lock(queue_mutex_);
    awaiting = awaiting_type_;
  }
  for (const auto& [input, source] : awaiting) {
    const auto seen = participant_.discovered_writer(topics::cue(source));
    if (!seen) continue;
    OutputOptions producer;
    producer.reliable = seen->reliable;
    producer.transient_local = seen->transient_local;
    try {
      subscribe(*input, source, producer, seen->type, std::nullopt,
                std::chrono::steady_clock::now() + std::chrono::milliseconds(2000));
      module_.log_->info("input {}/{}: subscribed to {} ({})", input->kernel(), input->name(),
                         topics::cue(source), seen->type);
    } catch (const std::exception& e) {
      std::lock_guard lock(queue_mutex_);
      awaiting_type_.erase(input);  // reported once, not every round
      module_.log_->error("input {}/{}: {}", input->kernel(), input->name(), e.what());
    }
  }
}

#if OSCAR_ZERO_COPY
namespace {
// The seq of the newest cue an input got; nothing before its first.
std::optional<std::uint64_t> newest_seq(const InputPort& input) {
  const auto entry = input.buffer().latest();
  if (!entry) return std::nullopt;
  return input.type().header.read(entry->cue.get()).seq();
}
}  // namespace
#endif

// On the configuration thread, every offer_poll(). Each input goes through three steps, one per
// call at most: its DDS reader got a cue and RouDi lists the source (a held feed subscribes);
// the reader's cues meet the feed's first (a cue published before the feed subscribed may still
// be on its way through DDS: a lost packet waits for the writer's heartbeat); then the reader
// is retired and the feed starts after the newest cue the input got.
void Module::Dds::switch_to_offered() {
#if OSCAR_ZERO_COPY
  // Past this, the switch goes on without the cues DDS still owes, and says which.
  constexpr auto kMeetBound = std::chrono::seconds(5);
  std::map<InputPort*, AwaitingOffer> awaiting;
  {
    std::lock_guard lock(queue_mutex_);
    awaiting = awaiting_offer_;
  }
  const auto keep = [&](InputPort* input, const AwaitingOffer& a) {
    std::lock_guard lock(queue_mutex_);
    if (const auto it = awaiting_offer_.find(input);
        it != awaiting_offer_.end() && it->second.source == a.source) {
      it->second = a;
    }
  };
  const auto settled = [&](InputPort* input) {
    std::lock_guard lock(queue_mutex_);
    awaiting_offer_.erase(input);
  };
  const auto now = std::chrono::steady_clock::now();
  for (auto& [input, a] : awaiting) {
    try {
      if (input->transfer() != Transfer::kPush) {
        switch_pulls_to_offered(*input, a);
        continue;
      }
      if (!a.feed) {
        {
          // Its producer runs once its cues come: then RouDi is asked whether it offers them.
          std::lock_guard lock(readers_mutex_);
          const auto it = readers_.find(input);
          if (it == readers_.end() || !it->second->received()) continue;
        }
        const auto topic = zero_copy::zero_copy_topic(domain_, topics::cue(a.source));
        if (!zero_copy::offered_on_this_host(topic, input->type().name)) continue;
        a.feed = std::make_shared<zero_copy::ChunkFeed>(topic, *input, input->type(), true);
        a.give_up = now + kMeetBound;
        keep(input, a);
        continue;
      }
      const auto first = a.feed->first_held();
      const auto last = newest_seq(*input);
      const bool met = first && last && *last + 1 >= *first;
      if (!met && now < a.give_up) continue;
      if (!a.feed->subscribed()) {  // RouDi did not connect it: from the start next round
        a.feed.reset();
        keep(input, a);
        continue;
      }
      std::unique_ptr<CueReader> reader;
      {
        std::lock_guard lock(readers_mutex_);
        if (const auto it = readers_.find(input); it != readers_.end()) {
          reader = std::move(it->second);
          readers_.erase(it);
        }
      }
      if (reader) reader->retire();
      const auto through = newest_seq(*input);
      a.feed->hand_over(through);
      {
        std::lock_guard lock(readers_mutex_);
        feeds_[input] = a.feed;
      }
      if (reader) participant_.subscriber().delete_datareader(reader->reader_);
      settled(input);
      module_.log_->info(
          "input {}/{}: {} is offered in shared memory on this host now: its cues come zero-copy "
          "from here on",
          input->kernel(), input->name(), a.source);
      if (!met && first && through && *first > *through + 1) {
        module_.log_->warn(
            "input {}/{}: cues {} to {} of {} came neither through DDS within {} s nor through "
            "shared memory",
            input->kernel(), input->name(), *through + 1, *first - 1, a.source,
            std::chrono::duration_cast<std::chrono::seconds>(kMeetBound).count());
      }
    } catch (const std::exception& e) {
      settled(input);
      module_.log_->warn("input {}/{}: its cues stay on DDS: {}", input->kernel(), input->name(),
                         e.what());
    }
  }
#endif
}

// Part of switch_to_offered(), for a pull or prefetch input: once RouDi lists the source, a
// mirror of its chunks subscribes; once RouDi connected it, it answers the input's pulls and the
// DDS pull source goes with its last user.
void Module::Dds::switch_pulls_to_offered(InputPort& input, AwaitingOffer& a) {
#if OSCAR_ZERO_COPY
  const auto update = [&](bool settled) {
    std::lock_guard lock(queue_mutex_);
    if (const auto it = awaiting_offer_.find(&input);
        it != awaiting_offer_.end() && it->second.source == a.source) {
      if (settled) {
        awaiting_offer_.erase(it);
      } else {
        it->second = a;
      }
    }
  };
  if (!a.pulls) {
    const auto topic = zero_copy::zero_copy_topic(domain_, topics::cue(a.source));
    if (!zero_copy::offered_on_this_host(topic, input.type().name)) return;
    a.pulls = std::make_shared<zero_copy::ChunkPullSource>(topic, a.source, input);
    update(false);
    return;
  }
  if (!a.pulls->subscribed()) return;
  input.set_pull_source(a.pulls);
  {
    std::lock_guard lock(readers_mutex_);
    pull_sources_[&input] = {a.pulls, a.source};
  }
  update(true);
  module_.log_->info(
      "input {}/{}: {} is offered in shared memory on this host now: its pulls are answered in "
      "this process from its chunks from here on",
      input.kernel(), input.name(), a.source);
#else
  (void)input;
  (void)a;
#endif
}

std::chrono::milliseconds Module::Dds::offer_poll() const {
  // Under queue_mutex_. A switch under way is looked at often: its feed holds the cues meanwhile.
  const bool switching =
      std::any_of(awaiting_offer_.begin(), awaiting_offer_.end(),
                  [](const auto& a) { return a.second.feed != nullptr || a.second.pulls; });
  return std::chrono::milliseconds(switching ? 5 : 250);
}

void Module::Dds::disconnect_input(InputPort& input) {
  decltype(awaiting_offer_)::node_type switching;  // its held feed ends outside the lock
  {
    std::lock_guard lock(queue_mutex_);
    awaiting_type_.erase(&input);
    switching = awaiting_offer_.extract(&input);
  }
  std::unique_ptr<CueReader> old;
  std::shared_ptr<PullSource> old_pull;  // the input reads elsewhere by now
  std::shared_ptr<void> old_feed;
  {
    std::lock_guard lock(readers_mutex_);
    if (auto it = feeds_.find(&input); it != feeds_.end()) {
      old_feed = std::move(it->second);
      feeds_.erase(it);
    }
    if (auto it = readers_.find(&input); it != readers_.end()) {
      old = std::move(it->second);
      readers_.erase(it);
    }
    if (auto it = pull_sources_.find(&input); it != pull_sources_.end()) {
      old_pull = std::move(it->second.source);
      pull_sources_.erase(it);
    }
  }
  if (old) participant_.subscriber().delete_datareader(old->reader_);
}

void Module::Dds::start_config() {
  const auto& name = module_.spec_.name;
  state_writer_ = std::make_unique<TopicWriter<ModuleState, ModuleStatePubSubType>>(
      participant_, topics::module_state());
  // A state-class reply: a client whose reader this writer has not matched yet still gets the
  // reply once it does (discovery is not symmetric in time).
  reply_writer_ = std::make_unique<TopicWriter<ConfigReply, ConfigReplyPubSubType>>(
      participant_, topics::config_reply(name));
  config_reader_ = std::make_unique<TopicReader<ConfigCommand, ConfigCommandPubSubType>>(
      participant_, topics::config(name),
      [this](const ConfigCommand& c, const eprosima::fastdds::dds::SampleInfo& info) {
        enqueue(c, info);
      });
  log_writer_ =
      std::make_unique<TopicWriter<LogRecord, LogRecordPubSubType>>(participant_, topics::log());
  announce_own_types();
  // The heartbeat: manual-by-topic liveliness with the module's lease (docs/architecture.md,
  // "Topics and QoS classes"). It stops when the process stops (SIGSTOP, crash) or a kernel call
  // outlives the watchdog.
  beat_writer_ = std::make_unique<TopicWriter<ModuleBeat, ModuleBeatPubSubType>>(
      participant_, topics::module_alive(module_.spec_.lease));
  {
    std::lock_guard lock(queue_mutex_);
    serving_ = true;
  }
  config_thread_ = std::thread([this] { serve_config(); });
  beat_thread_ = std::thread([this] { beat(); });
  module_.log_sink_->attach(&log_writer_->dds_writer());
}

// Every participant of a process shares its GUID prefix's host and process part, and those made
// in a module's process say which modules it hosts (DdsParticipant::modules_in_process_of): a
// kernel that writes a command from a participant of its own, under any name, is still seen
// coming from its module's process. Only modules of this module's system count (not a test's
// embedded modules).
CommandOrigin Module::Dds::origin_of(const eprosima::fastdds::dds::SampleInfo& info) {
  CommandOrigin origin;
  if (trusted_writers_) {
    origin.identity = trusted_writers_->of(info.sample_identity.writer_guid().guidPrefix);
  }
  const auto& system = module_.spec_.system_modules;
  for (auto& m : participant_.modules_in_process_of(info.sample_identity.writer_guid())) {
    if (std::find(system.begin(), system.end(), m) != system.end() &&
        std::find(origin.modules.begin(), origin.modules.end(), m) == origin.modules.end()) {
      origin.modules.push_back(std::move(m));
    }
  }
  return origin;
}

void Module::Dds::enqueue(const ConfigCommand& c, const eprosima::fastdds::dds::SampleInfo& info) {
  const auto now = std::chrono::steady_clock::now();
  const auto writer =
      fmt::format("{}", fmt::streamed(info.sample_identity.writer_guid().guidPrefix));
  {
    std::lock_guard lock(queue_mutex_);
    if (!rate_limit_.admit(writer, now)) return;  // reported by the configuration thread
    if (queue_.size() >= kMaxQueuedCommands) {
      ++queue_full_drops_;
      return;
    }
  }
  auto origin = origin_of(info);  // asks discovery: not under the queue's lock
  std::lock_guard lock(queue_mutex_);
  if (queue_.size() >= kMaxQueuedCommands) {  // filled by another DDS thread meanwhile
    ++queue_full_drops_;
    return;
  }
  queue_.push_back({c, std::move(origin)});
  queue_cv_.notify_all();
}

void Module::Dds::report_drops() {
  std::optional<std::string> over_rate;
  std::uint64_t queue_full = 0;
  {
    std::lock_guard lock(queue_mutex_);
    over_rate = rate_limit_.report(std::chrono::steady_clock::now());
    if (over_rate || queue_full_drops_ > 0) std::swap(queue_full, queue_full_drops_);
  }
  if (over_rate) module_.log_->warn("{}", *over_rate);
  if (queue_full > 0) {
    module_.log_->warn("dropped {} configuration command(s): {} were waiting already", queue_full,
                       kMaxQueuedCommands);
  }
}

void Module::Dds::check_shared_memory_port() {
  const auto lost = port_file_watch_.lost();
  if (!lost) return;
  module_.end_for_restart(fmt::format(
      "its shared-memory port {} was removed or replaced by another process (systemd-logind's "
      "RemoveIPC does so at the end of the user's last session, see docs/boot.md): a process that "
      "starts sending to it would never reach this module; the registry starts it again",
      *lost));
}

// Commands are applied on their own thread, never inside a DDS callback: a rewire creates and
// deletes readers, and activate waits for the processing thread.
void Module::Dds::serve_config() {
  std::unique_lock lock(queue_mutex_);
  const auto ready = [&] { return !serving_ || !queue_.empty() || !refollow_.empty(); };
  auto next_offer_poll = std::chrono::steady_clock::now();  // switch_to_offered()
  auto next_roudi_poll = std::chrono::steady_clock::now();  // join_roudi_later()
  auto next_port_check = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (true) {
    // Discovery is polled for raw inputs whose source has not shown up yet, RouDi for plain
    // inputs whose source it does not list yet; dropped commands are reported within a second.
    auto poll = std::chrono::milliseconds(awaiting_type_.empty() ? 1000 : 50);
    if (!awaiting_offer_.empty()) poll = std::min(poll, offer_poll());
    queue_cv_.wait_for(lock, poll, ready);
    if (!serving_) return;
    lock.unlock();
    report_drops();
    lock.lock();
    if (!awaiting_type_.empty()) {
      lock.unlock();
      subscribe_discovered();
      lock.lock();
    }
    if (std::chrono::steady_clock::now() >= next_port_check) {
      next_port_check = std::chrono::steady_clock::now() + std::chrono::seconds(1);
      lock.unlock();
      check_shared_memory_port();
      lock.lock();
    }
    if (roudi_later_ && std::chrono::steady_clock::now() >= next_roudi_poll) {
      next_roudi_poll = std::chrono::steady_clock::now() + std::chrono::seconds(1);
      lock.unlock();
      join_roudi_later();
      lock.lock();
    }
    if (!awaiting_offer_.empty() && std::chrono::steady_clock::now() >= next_offer_poll) {
      next_offer_poll = std::chrono::steady_clock::now() + offer_poll();
      lock.unlock();
      switch_to_offered();
      lock.lock();
    }
    if (!refollow_.empty()) {
      const auto r = std::move(refollow_.front());
      refollow_.pop_front();
      lock.unlock();
      refollow(r);
      lock.lock();
      continue;
    }
    if (queue_.empty()) continue;
    auto [command, origin] = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    // A repeated command (same sender and id: the client did not see our reply) is answered
    // again, not applied twice. A sender over its limit is refused and not remembered.
    if (const auto* last = last_replies_.find(command.sender(), command.id())) {
      reply_writer_->write(*last);
    } else {
      const auto reply = module_.apply(command, origin);
      if (command.sender().size() <= internal::kMaxSenderChars) {
        last_replies_.remember(command.sender(), reply);
      }
      reply_writer_->write(reply);
    }
    lock.lock();
  }
}

// Every lease/3 a heartbeat (unless a kernel hangs); every second the module state, whose
// counters give `oscar ps` its rates.
void Module::Dds::beat() {
  const auto period = std::max(module_.spec_.lease / 3, std::chrono::milliseconds(1));
  ModuleBeat b;
  b.module_name(module_.spec_.name);
  b.incarnation(module_.spec_.incarnation);
  b.pid(static_cast<std::int32_t>(getpid()));
  auto next_state = std::chrono::steady_clock::now();
  std::unique_lock lock(queue_mutex_);
  while (serving_) {
    lock.unlock();
    if (!module_.hung()) beat_writer_->write(b);
    if (std::chrono::steady_clock::now() >= next_state) {
      publish_state(module_.state());
      next_state += std::chrono::seconds(1);
    }
    lock.lock();
    queue_cv_.wait_for(lock, period, [&] { return !serving_; });
  }
}

void Module::Dds::stop_config() {
  {
    std::lock_guard lock(queue_mutex_);
    if (!serving_) return;
    serving_ = false;
    queue_cv_.notify_all();
  }
  if (config_thread_.joinable()) config_thread_.join();
  if (beat_thread_.joinable()) beat_thread_.join();
  config_reader_.reset();
}

// The IDL texts of the types its ports use that OSCAR does not define, for the tools
// (oscar/type_texts.hpp); a module of OSCAR's types alone makes no writer for them.
void Module::Dds::announce_own_types() {
  std::vector<const KernelPorts*> kernels;
  for (const auto& slot : module_.slots_) kernels.push_back(&slot->instance->ports());
  try {
    types_writer_ = announce_type_texts(participant_, module_.spec_.name, own_type_texts(kernels));
  } catch (const std::runtime_error& e) {
    // The module works without it; only the tools cannot decode its own types then.
    module_.log_->warn("the IDL texts of its own types are not announced: {}", e.what());
  }
}

void Module::Dds::publish_state(const ModuleState& state) {
  if (state_writer_) state_writer_->write(state);
}

}  // namespace oscar
