#pragma once
/// @file Outputs: the producer end of a channel. In-process consumers get the same immutable
/// cue (no copy, no serialisation); the frame also hands it to DDS when it leaves the process.

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "oscar/cue.hpp"
#include "oscar/ring_buffer.hpp"

namespace oscar {

class InputPort;

struct OutputOptions {
  std::size_t depth = 16;
  bool reliable = true;
  bool transient_local = false;  ///< late joiners get the history (up to depth)
};

/// Keeps an output's cues in shared memory, where the zero-copy path carries them to the other
/// processes of the host (docs/zero_copy.md); the frame sets one for an output of a plain type.
class CueChunks {
 public:
  virtual ~CueChunks() = default;
  /// A default cue in a fresh chunk, to be filled and published; nullptr when none is left.
  virtual std::shared_ptr<void> loan() = 0;
  /// Publishes `cue` to the host's other processes: in place if it is a loan() that nobody else
  /// holds, else copied into a fresh chunk. Returns the cue as they read it (the published chunk,
  /// which the ring then keeps), or `cue` itself if it could not be published (it says why).
  virtual std::shared_ptr<const void> publish(std::shared_ptr<const void> cue) = 0;
};

/// The type-independent part of an output; the framework works with this.
class OutputPort {
 public:
  OutputPort(std::string kernel, std::string name, const CueTypeInfo& type, OutputOptions options);
  virtual ~OutputPort() = default;
  OutputPort(const OutputPort&) = delete;
  OutputPort& operator=(const OutputPort&) = delete;

  const std::string& kernel() const { return kernel_; }
  const std::string& name() const { return name_; }
  /// "<kernel>/<channel>": how inputs name this output.
  std::string address() const { return kernel_ + "/" + name_; }
  const CueTypeInfo& type() const { return type_; }
  const OutputOptions& options() const { return options_; }
  RingBuffer& buffer() { return buffer_; }
  std::uint64_t published() const { return buffer_.pushed(); }

  /// Completes the header (source, seq, and the generation stamp if the kernel set none),
  /// stores the cue in the ring buffer, hands it to in-process inputs and to the remote hook.
  void publish_erased(std::shared_ptr<void> cue);
  /// Re-publishes a cue exactly as it is (replay): header untouched.
  void forward_erased(std::shared_ptr<const void> cue);
  /// A default cue to fill and publish: in a chunk where the zero-copy path carries this output,
  /// else on the heap.
  std::shared_ptr<void> loan_erased();

  /// Hands every cue to `input` too.
  /// @throws std::invalid_argument if the types differ or check_reliability() refuses the pair.
  void connect(InputPort* input);
  void disconnect(InputPort* input);
  /// The frame's DDS writer; called on the publishing thread after in-process delivery.
  void set_remote(std::function<void(const void*)> remote);
  /// The zero-copy path's chunks for this output, or nullptr for none.
  void set_chunks(std::shared_ptr<CueChunks> chunks);
  /// The clock that stamps generation times (wall clock by default; harnesses set their own).
  void set_clock(std::function<Stamp()> clock);
  /// Continues numbering after `*counter` and stores every new number there (the frame points
  /// it into a file that outlives the process, so a restart never repeats a number).
  void persist_sequence(std::uint64_t* counter);

 private:
  // Stores the cue in the ring and hands it on; called with mutex_ held.
  void hand_over(const std::shared_ptr<const void>& cue, Stamp generated);

  std::string kernel_, name_;
  const CueTypeInfo& type_;
  OutputOptions options_;
  RingBuffer buffer_;
  std::uint64_t seq_ = 0;
  std::uint64_t* persisted_seq_ = nullptr;
  std::mutex mutex_;  // guards consumers_, remote_, clock_ against rewiring
  std::vector<InputPort*> consumers_;
  std::function<void(const void*)> remote_;
  std::function<Stamp()> clock_;
  std::shared_ptr<CueChunks> chunks_;
};

/// @throws std::invalid_argument naming both ends if `input` does not take the cue type `type` of
///         the output `source` ("<kernel>/<channel>"): their types differ and the input is no raw
///         input (which takes any type).
void check_types(const InputPort& input, const std::string& source, const CueTypeInfo& type);

/// @throws std::invalid_argument naming both ends if `input` declares reliable delivery and the
///         output `source` ("<kernel>/<channel>", declared `declared`) is best effort: a reliable
///         reader never matches a best-effort writer (docs/architecture.md, "Topics and QoS
///         classes"), so no cue would ever arrive.
void check_reliability(const InputPort& input, const std::string& source,
                       const OutputOptions& declared);

/// A typed output handle, as KernelSetup::output<T>() returns it.
template <CueType T>
class Output final : public OutputPort {
 public:
  using OutputPort::OutputPort;

  /// A cue to fill where it lies and then publish: for a plain type on the zero-copy path, in
  /// the shared-memory chunk the host's consumers will read it from (docs/zero_copy.md).
  class Loan {
   public:
    T& operator*() const { return *static_cast<T*>(cue_.get()); }
    T* operator->() const { return static_cast<T*>(cue_.get()); }

   private:
    friend class Output;
    explicit Loan(std::shared_ptr<void> cue) : cue_(std::move(cue)) {}
    std::shared_ptr<void> cue_;
  };

  /// A default-constructed cue to fill and publish(); dropped unpublished, it goes back.
  Loan loan() { return Loan(loan_erased()); }
  /// Publishes one cue; the frame fills in header.source and header.seq.
  void publish(T cue) { publish_erased(std::make_shared<T>(std::move(cue))); }
  /// Publishes a loaned cue without copying it.
  void publish(Loan cue) { publish_erased(std::move(cue.cue_)); }
};

}  // namespace oscar
