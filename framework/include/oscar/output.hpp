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

  /// Hands every cue to `input` too.
  /// @throws std::invalid_argument if the types differ or check_reliability() refuses the pair.
  void connect(InputPort* input);
  void disconnect(InputPort* input);
  /// The frame's DDS writer; called on the publishing thread after in-process delivery.
  void set_remote(std::function<void(const void*)> remote);
  /// The clock that stamps generation times (wall clock by default; harnesses set their own).
  void set_clock(std::function<Stamp()> clock);
  /// Continues numbering after `*counter` and stores every new number there (the frame points
  /// it into a file that outlives the process, so a restart never repeats a number).
  void persist_sequence(std::uint64_t* counter);

 private:
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
  /// Publishes one cue; the frame fills in header.source and header.seq.
  void publish(T cue) { publish_erased(std::make_shared<T>(std::move(cue))); }
};

}  // namespace oscar
