#pragma once
/// @file Inputs: the consumer end of a channel, with its ring buffer and transfer
/// (docs/architecture.md).

#include <chrono>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "oscar/cue.hpp"
#include "oscar/ring_buffer.hpp"

namespace oscar {

/// How an input gets its cues (docs/architecture.md).
enum class Transfer {
  kPush,     ///< the producer publishes; cues arrive in the ring buffer (default)
  kPull,     ///< the consumer asks the producer's output ring buffer on demand
  kPrefetch  ///< a non-blocking pull that returns a future
};
/// "push", "pull" or "prefetch".
const char* to_string(Transfer t);
/// @throws std::invalid_argument for any other text.
Transfer parse_transfer(std::string_view text);

/// Which cue of the producer's ring a pull asks for.
enum class PullQuery {
  kLatest,      ///< the newest cue
  kAtOrBefore,  ///< the newest cue generated at or before t
  kNearest,     ///< the cue generated nearest to t
  kAtOrAfter    ///< the first cue generated at or after t; the producer holds the request until
                ///< such a cue is in its ring, up to the pull's wait, and then answers nothing
};

/// The longest wait a pull may ask the producer to hold it (PullQuery::kAtOrAfter).
inline constexpr std::chrono::seconds kMaxPullWait{10};
/// How many held pulls (PullQuery::kAtOrAfter) one consumer input may have at a producer at once.
inline constexpr std::size_t kMaxHeldPulls = 16;

/// Which cues of the producer's ring a block pull asks for: its n newest, or those generated in
/// [t0, t1]. The answer is oldest first.
struct PullBlock {
  enum class Kind { kLatest, kRange };
  Kind kind = Kind::kLatest;
  std::size_t n = 0;  ///< kLatest: how many (fewer come if the producer's ring holds fewer)
  Stamp t0 = 0;       ///< kRange: the start
  Stamp t1 = 0;       ///< kRange: the end
  /// The producer's n newest cues.
  static PullBlock latest(std::size_t n) { return {Kind::kLatest, n, 0, 0}; }
  /// The producer's cues generated in [t0, t1] (a pull checks t0 <= t1).
  static PullBlock range(Stamp t0, Stamp t1) { return {Kind::kRange, 0, t0, t1}; }
};

/// The answer to a block pull: type-erased cues, oldest first.
using CueBlock = std::vector<std::shared_ptr<const void>>;

/// What delivery an input asks of its producer's output (docs/architecture.md, "Topics and QoS
/// classes").
enum class Reliability {
  kAsProducer,  ///< reliable or best effort as the producer's output is declared (default)
  kReliable,    ///< needs every cue: wiring it to a best-effort output is refused
  kBestEffort   ///< reads best effort, whatever the producer offers
};

struct InputOptions {
  std::size_t depth = 16;
  Transfer transfer = Transfer::kPush;
  Reliability reliability = Reliability::kAsProducer;  ///< declared by the kernel, not the YAML
};

/// What the configuration (a system or module file) sets for one input: each field it names
/// replaces the kernel's declared value, the others stand.
struct InputOverrides {
  std::optional<std::size_t> depth;
  std::optional<Transfer> transfer;
  InputOptions applied_to(InputOptions declared) const {
    if (depth) declared.depth = *depth;
    if (transfer) declared.transfer = *transfer;
    return declared;
  }
};

/// Answers pulls for one input: the producer's ring in this process, or a request over DDS.
class PullSource {
 public:
  virtual ~PullSource() = default;
  /// Resolves to the cue, or to nullptr if the producer holds none that matches (for
  /// kAtOrAfter: none within `wait`).
  /// @throws std::length_error if kMaxHeldPulls of this input's pulls are held already.
  virtual std::shared_future<std::shared_ptr<const void>> request(
      PullQuery query, Stamp t, std::chrono::nanoseconds wait) = 0;
  /// Resolves to the cues of the block, oldest first (none if the producer holds none).
  virtual std::shared_future<CueBlock> request(const PullBlock& block) = 0;
};

/// The type-independent part of an input; the framework works with this.
class InputPort {
 public:
  InputPort(std::string kernel, std::string name, const CueTypeInfo& type, InputOptions options);
  virtual ~InputPort() = default;
  InputPort(const InputPort&) = delete;
  InputPort& operator=(const InputPort&) = delete;

  const std::string& kernel() const { return kernel_; }
  const std::string& name() const { return name_; }
  /// The declared cue type; raw_cue_type() for an input that takes cues of any type.
  const CueTypeInfo& type() const { return type_; }
  /// True for a raw input (KernelSetup::raw_input): it takes cues of any type, as RawCue.
  bool takes_any_type() const;
  Transfer transfer() const { return transfer_; }
  Reliability reliability() const { return reliability_; }
  RingBuffer& buffer() { return buffer_; }
  const RingBuffer& buffer() const { return buffer_; }

  /// Delivers a cue of the producer's type `producer`: stores it, stamped with its receive time,
  /// and runs the arrival hook. A raw input gets it as RawCue, serialized (raw_cue.hpp); any
  /// other input gets it as it is (the types were checked when wiring).
  void deliver_from(const CueTypeInfo& producer, std::shared_ptr<const void> cue);
  /// The same for a cue whose generation stamp the caller holds: an output of this process that
  /// has just completed the cue's header, so that the header is not read again on the way.
  void deliver_from(const CueTypeInfo& producer, std::shared_ptr<const void> cue, Stamp generated);
  /// Called after every delivery, on the delivering thread (the frame triggers kernels with it).
  void set_arrival_hook(std::function<void()> hook);
  void set_pull_source(std::shared_ptr<PullSource> source);
  /// Asks the producer; the answer is also stored in the ring buffer. A kAtOrAfter query is held
  /// by the producer up to `wait` (other queries are answered at once).
  /// @throws std::logic_error if the input is not connected to a producer.
  /// @throws std::invalid_argument if `wait` is negative or longer than kMaxPullWait.
  /// @throws std::length_error if kMaxHeldPulls of this input's pulls are held already.
  std::shared_future<std::shared_ptr<const void>> request(PullQuery query, Stamp t,
                                                          std::chrono::nanoseconds wait = {});
  /// Asks the producer for a block of cues; the answer is also stored in the ring buffer.
  /// @throws std::logic_error if the input is not connected to a producer.
  /// @throws std::invalid_argument for a range whose start is after its end.
  std::shared_future<CueBlock> request(const PullBlock& block);

 protected:
  std::uint64_t seen_index_ = 0;  // newest entry handed out by wait_next

 private:
  std::shared_ptr<PullSource> pull_source();  // @throws std::logic_error if there is none

  std::string kernel_, name_;
  const CueTypeInfo& type_;
  Transfer transfer_;
  Reliability reliability_;
  bool takes_any_type_;
  RingBuffer buffer_;
  std::mutex hooks_mutex_;
  // Shared, so that a delivery copies a pointer, not the hook and what it captured.
  std::shared_ptr<const std::function<void()>> arrival_hook_;
  std::shared_ptr<PullSource> pull_source_;
};

/// A cue that a prefetch will deliver.
template <CueType T>
class CueFuture {
 public:
  explicit CueFuture(std::shared_future<std::shared_ptr<const void>> f) : f_(std::move(f)) {}
  /// True once the answer is there (then get() does not block).
  bool ready() const { return f_.wait_for(std::chrono::seconds(0)) == std::future_status::ready; }
  /// Waits up to `timeout`; nullptr if the producer had nothing or did not answer in time.
  std::shared_ptr<const T> get(std::chrono::nanoseconds timeout = std::chrono::seconds(1)) const {
    if (f_.wait_for(timeout) != std::future_status::ready) return nullptr;
    return std::static_pointer_cast<const T>(f_.get());
  }

 private:
  std::shared_future<std::shared_ptr<const void>> f_;
};

/// The cues a block prefetch will deliver.
template <CueType T>
class CueBlockFuture {
 public:
  explicit CueBlockFuture(std::shared_future<CueBlock> f) : f_(std::move(f)) {}
  /// True once the answer is there (then get() does not block).
  bool ready() const { return f_.wait_for(std::chrono::seconds(0)) == std::future_status::ready; }
  /// Waits up to `timeout`: the cues, oldest first; none if the producer had none or did not
  /// answer in time.
  std::vector<std::shared_ptr<const T>> get(
      std::chrono::nanoseconds timeout = std::chrono::seconds(1)) const {
    std::vector<std::shared_ptr<const T>> out;
    if (f_.wait_for(timeout) != std::future_status::ready) return out;
    const auto& cues = f_.get();
    out.reserve(cues.size());
    for (const auto& c : cues) out.push_back(std::static_pointer_cast<const T>(c));
    return out;
  }

 private:
  std::shared_future<CueBlock> f_;
};

/// A typed input handle, as KernelSetup::input<T>() returns it.
template <CueType T>
class Input final : public InputPort {
 public:
  using Ptr = std::shared_ptr<const T>;
  using InputPort::InputPort;

  /// The newest cue, or nullptr.
  Ptr latest() const { return cast(buffer().latest()); }
  /// The n newest cues, oldest first.
  std::vector<Ptr> latest(std::size_t n) const { return cast(buffer().latest(n)); }
  /// The newest cue generated at or before t, or nullptr.
  Ptr at_or_before(Stamp t) const { return cast(buffer().at_or_before(t)); }
  /// The cue generated nearest to t, or nullptr.
  Ptr nearest(Stamp t) const { return cast(buffer().nearest(t)); }
  /// The cues generated in [t0, t1], oldest first. @throws std::invalid_argument if t0 > t1.
  std::vector<Ptr> range(Stamp t0, Stamp t1) const { return cast(buffer().range(t0, t1)); }
  /// The next cue after the last one this call returned, waiting up to `timeout`.
  Ptr wait_next(std::chrono::nanoseconds timeout) {
    auto e = buffer().wait_next(seen_index_, timeout);
    if (!e) return nullptr;
    seen_index_ = e->index;
    return std::static_pointer_cast<const T>(e->cue);
  }
  /// A cue with the time it reached this input.
  struct Received {
    Ptr cue;
    Stamp received;
  };
  /// Every cue that arrived since the last take_new() or wait_next(), oldest first (cues the
  /// ring buffer already evicted are lost: size the depth for the rate).
  std::vector<Received> take_new() {
    std::vector<Received> out;
    for (const auto& e : buffer().latest(buffer().depth())) {
      if (e.index <= seen_index_) continue;
      out.push_back({std::static_pointer_cast<const T>(e.cue), e.received});
      seen_index_ = e.index;
    }
    return out;
  }
  /// Pulls the producer's newest cue (pull transfer); nullptr if none or no answer in time.
  Ptr pull(std::chrono::nanoseconds timeout = std::chrono::seconds(1)) {
    return CueFuture<T>(request(PullQuery::kLatest, 0)).get(timeout);
  }
  /// Pulls the producer's cue at or before (or nearest to, or first at or after) t. For
  /// kAtOrAfter the producer holds the pull up to `timeout` (at most kMaxPullWait).
  Ptr pull_at(Stamp t, PullQuery query = PullQuery::kAtOrBefore,
              std::chrono::nanoseconds timeout = std::chrono::seconds(1)) {
    const auto wait = query == PullQuery::kAtOrAfter ? timeout : std::chrono::nanoseconds{};
    return CueFuture<T>(request(query, t, wait)).get(timeout);
  }
  /// Starts a pull and returns at once (prefetch transfer). `wait`: how long the producer may
  /// hold a kAtOrAfter pull for a matching cue (at most kMaxPullWait); then it answers nothing.
  /// @throws std::invalid_argument if `wait` is negative or longer than kMaxPullWait.
  /// @throws std::length_error if kMaxHeldPulls of this input's pulls are held already.
  CueFuture<T> prefetch(PullQuery query = PullQuery::kLatest, Stamp t = 0,
                        std::chrono::nanoseconds wait = {}) {
    return CueFuture<T>(request(query, t, wait));
  }
  /// Pulls the producer's n newest cues, oldest first (fewer if its ring holds fewer); none if it
  /// has none or did not answer in time.
  std::vector<Ptr> pull_latest(std::size_t n,
                               std::chrono::nanoseconds timeout = std::chrono::seconds(1)) {
    return prefetch(PullBlock::latest(n)).get(timeout);
  }
  /// Pulls the producer's cues generated in [t0, t1], oldest first.
  /// @throws std::invalid_argument if t0 > t1.
  std::vector<Ptr> pull_range(Stamp t0, Stamp t1,
                              std::chrono::nanoseconds timeout = std::chrono::seconds(1)) {
    return prefetch(PullBlock::range(t0, t1)).get(timeout);
  }
  /// Starts a block pull and returns at once (prefetch transfer).
  /// @throws std::invalid_argument for a range whose start is after its end.
  CueBlockFuture<T> prefetch(const PullBlock& block) { return CueBlockFuture<T>(request(block)); }

 private:
  static Ptr cast(const std::optional<RingEntry>& e) {
    return e ? std::static_pointer_cast<const T>(e->cue) : nullptr;
  }
  static std::vector<Ptr> cast(const std::vector<RingEntry>& entries) {
    std::vector<Ptr> out;
    out.reserve(entries.size());
    for (const auto& e : entries) out.push_back(std::static_pointer_cast<const T>(e.cue));
    return out;
  }
};

}  // namespace oscar
