#pragma once
// The DDS side of a module frame: cue writers and readers, the configuration topic and its
// replies, module state and log records (docs/architecture.md, "Topics and QoS classes").

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>

#include "command_rate_limit.hpp"
#include "dds/discovery.hpp"
#include "dds/module_wishes.hpp"
#include "dds/pull.hpp"
#include "dds/writer_identity.hpp"
#include "module_slot.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/module.hpp"
#include "oscar/shared_memory.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "oscar/type_texts.hpp"
#include "reply_memory.hpp"

namespace oscar::zero_copy {
class ChunkFeed;
class ChunkPullSource;
}  // namespace oscar::zero_copy

namespace oscar {

class Module::Dds {
 public:
  Dds(Module& module, int domain);
  ~Dds();

  void wire_outputs(std::vector<std::unique_ptr<Slot>>& slots);
  /// The kernels' resource wishes to the coordinator and its answers (module_wishes.hpp), if
  /// any kernel declares one.
  void wire_wishes(std::vector<std::unique_ptr<Slot>>& slots);
  /// Sends the wishes again if they changed (a kernel was activated or deactivated).
  void publish_wishes() {
    if (wishes_) wishes_->publish();
  }
  /// Connects `input` to the remote `source`: a push input subscribes to its topic, a pull or
  /// prefetch input asks its producer. Waits (at most 2 s) until matched; a rewire
  /// (`switch_wait`) also waits that long for the source's first cue, so that nothing it
  /// publishes after the switch is lost. Only then is an earlier subscription of the input
  /// dropped. The reader's QoS follows the producer's declared class (qos::cue_reader), as
  /// discovery shows its writer. A raw input reads the type discovery shows too; while no
  /// writer of the source is seen it has no reader, and the configuration thread subscribes it
  /// once one is. Returns what did not happen in time, or "".
  /// @throws std::invalid_argument as check_reliability() does.
  std::string connect_input(InputPort& input, const std::string& source,
                            std::optional<std::chrono::milliseconds> switch_wait);
  /// Drops the input's subscription or pull requester, if it has one.
  void disconnect_input(InputPort& input);
  void start_config();
  void stop_config();
  void publish_state(const ModuleState& state);

 private:
  void announce_own_types();
  class CueReader;
  class OutputWriter;
  /// A reader to make again, asking no more than the producer's writer offers.
  struct Refollow {
    InputPort* input;
    std::string source;
    OutputOptions offered;
  };
  /// The zero-copy path (docs/zero_copy.md): a module with ports of a plain cue type joins this
  /// host's RouDi, if one runs, else once one does (join_roudi_later()).
  void join_zero_copy();
  /// Joins this host's RouDi; why not if it cannot (roudi_later_ is set if none runs yet).
  std::optional<std::string> join_roudi();
  /// If RouDi runs now: joins it, offers the plain outputs' chunks and lets the plain push
  /// inputs on DDS switch as their producers offer (switch_to_offered()).
  void join_roudi_later();
  /// Gives a plain output its chunks in shared memory, if the module joined RouDi; true if so.
  bool offer_chunks(OutputPort& out);
  /// Feeds a push input of a plain type from its producer's chunks when this host's RouDi lists
  /// the producer's output (chunks_offered(), waiting a moment if the producer's writer was
  /// seen: `producer_seen`); "" then, nothing if its cues go through DDS (one line says why).
  std::optional<std::string> feed_zero_copy(InputPort& input, const std::string& source,
                                            bool producer_seen);
  /// Whether this host's RouDi lists the chunks of `source` for `input`, a plain input: waits up
  /// to `until` for them, and up to 300 ms (RouDi's next discovery round) after the producer's
  /// writer shows. Says why not in one line, and keeps an input whose producer may offer them
  /// later for switch_to_offered().
  bool chunks_offered(InputPort& input, const std::string& source,
                      std::chrono::steady_clock::time_point until);
  /// Answers a pull or prefetch input of a plain type in this process from its producer's
  /// chunks (zero_copy::ChunkPullSource) when this host's RouDi lists them (chunks_offered(),
  /// up to `until`); "" then, nothing if its pulls go to the producer over DDS.
  std::optional<std::string> pull_zero_copy(InputPort& input, const std::string& source,
                                            std::chrono::steady_clock::time_point until);
  /// What the module's participant learns of from the discovery servers, if it uses them:
  /// only what shares a topic with it (docs/network.md), unless an input takes any type.
  static DiscoveryScope discovery_scope_of(const Module& module);
  static NetworkConfig network_of(const Module& module);
  /// A plain client of the discovery servers learns of a writer only once it reads the topic:
  /// makes a reader of the topic that matches no writer (exclusive ownership), which makes the
  /// servers tell this participant of the source's writer, waits for it (at most until `until`)
  /// and deletes the reader, which never received anything. Returns the producer's writer as
  /// discovery then shows it, if it does.
  std::optional<DdsParticipant::DiscoveredWriter> ask_servers_for_producer(
      InputPort& input, const std::string& source, std::chrono::steady_clock::time_point until);
  std::string subscribe(InputPort& input, const std::string& source, const OutputOptions& producer,
                        const std::string& type,
                        std::optional<std::chrono::milliseconds> switch_wait,
                        std::chrono::steady_clock::time_point until);
  void subscribe_discovered();
  /// Inputs of a plain type that read through DDS only because no process of this host offered
  /// their producer's chunks when they were wired go zero-copy once one does. A push input: a
  /// held feed subscribes, the DDS reader is retired and the feed starts after its last cue. A
  /// pull input: switch_pulls_to_offered().
  void switch_to_offered();
  struct AwaitingOffer;
  void switch_pulls_to_offered(InputPort& input, AwaitingOffer& a);
  /// How often switch_to_offered() runs (under queue_mutex_).
  std::chrono::milliseconds offer_poll() const;
  void follow_producer(InputPort& input, const std::string& source, const OutputOptions& offered);
  void refollow(const Refollow& r);
  void serve_config();
  /// Every second (on the configuration thread): ends the module for a restart once its
  /// shared-memory port file has not been the one it listens on for 3 looks in a row.
  void check_shared_memory_port();
  void beat();

  Module& module_;
  const int domain_;
  bool zero_copy_ = false;    ///< joined this host's RouDi
  bool roudi_later_ = false;  ///< has plain ports, found no RouDi: join_roudi_later() polls
  const DiscoveryScope discovery_scope_;  ///< discovery_scope_of(module_), before participant_
  DdsParticipant participant_;
  /// A plain client of discovery servers: it learns of a producer's writer only by reading the
  /// producer's topic (ask_servers_for_producer).
  bool learns_only_shared_topics_ = false;
  std::vector<std::unique_ptr<OutputWriter>> writers_;
  std::vector<std::unique_ptr<internal::DdsPullServer>> pull_servers_;
  /// The pull and prefetch inputs' sources, over DDS or zero-copy, and where they pull from.
  struct PullWiring {
    std::shared_ptr<PullSource> source;
    std::string from;
  };
  std::map<InputPort*, PullWiring> pull_sources_;
  std::mutex readers_mutex_;
  std::map<InputPort*, std::unique_ptr<CueReader>> readers_;
  /// Push inputs fed by the zero-copy path (zero_copy::ChunkFeed, which only the zero-copy build
  /// knows), under readers_mutex_.
  std::map<InputPort*, std::shared_ptr<void>> feeds_;
  std::vector<OutputPort*> chunked_outputs_;  ///< outputs given zero-copy chunks
  PortFileWatch port_file_watch_{participant_.shared_memory_port()};
  /// Ends the module when the RouDi it joined is replaced (zero_copy::RoudiWatch).
  std::shared_ptr<void> roudi_watch_;

  // The configuration endpoints (topics::...), made by start_config().
  std::unique_ptr<TopicWriter<ModuleState, ModuleStatePubSubType>> state_writer_;
  std::unique_ptr<TopicWriter<ConfigReply, ConfigReplyPubSubType>> reply_writer_;
  std::unique_ptr<TopicWriter<LogRecord, LogRecordPubSubType>> log_writer_;
  /// Only in a module whose ports use types OSCAR does not define (announce_own_types()).
  std::unique_ptr<TypeTextsWriter> types_writer_;
  std::unique_ptr<TopicReader<ConfigCommand, ConfigCommandPubSubType>> config_reader_;
  std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  struct Command {
    ConfigCommand command;
    CommandOrigin origin;
  };
  // The modules of the running system living in the process that wrote a command, and in a
  // secured system the identity it authenticated as.
  CommandOrigin origin_of(const eprosima::fastdds::dds::SampleInfo& info);
  // Secured systems: the identities whose commands count, by their certificates.
  std::optional<internal::WriterIdentities> trusted_writers_;
  // Called on a DDS thread for each command: queues it unless its writer is over its rate or
  // the queue is full.
  void enqueue(const ConfigCommand& c, const eprosima::fastdds::dds::SampleInfo& info);
  // On the configuration thread: a line for each kind of drop, at most once a second.
  void report_drops();
  /// Commands waiting to be applied, at most: a second of every writer at its full rate cannot
  /// grow the queue without bound, and an honest command waits behind no more than these.
  static constexpr std::size_t kMaxQueuedCommands = 256;
  std::deque<Command> queue_;
  internal::CommandRateLimit rate_limit_;  // under queue_mutex_
  std::uint64_t queue_full_drops_ = 0;     // under queue_mutex_; reported and reset
  std::deque<Refollow> refollow_;          // served by the configuration thread, like queue_
  std::map<InputPort*, std::string> awaiting_type_;  // raw inputs whose source is not seen yet
  /// Inputs read through DDS until their source is offered on this host (switch_to_offered()),
  /// under queue_mutex_; `feed` is held while the switch is under way.
  struct AwaitingOffer {
    std::string source;
    std::shared_ptr<zero_copy::ChunkFeed> feed{};  ///< a push input's, held
    std::chrono::steady_clock::time_point give_up{};
    std::shared_ptr<zero_copy::ChunkPullSource> pulls{};  ///< a pull input's, until connected
  };
  std::map<InputPort*, AwaitingOffer> awaiting_offer_;
  internal::ReplyMemory last_replies_;  // the configuration thread's: answers repeated commands
  bool serving_ = false;
  std::thread config_thread_;
  std::unique_ptr<TopicWriter<ModuleBeat, ModuleBeatPubSubType>> beat_writer_;
  std::thread beat_thread_;
  std::unique_ptr<internal::ModuleWishes> wishes_;
};

}  // namespace oscar
