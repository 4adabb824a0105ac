#pragma once
/// @file KernelHarness: drives one kernel without DDS and without other processes
/// (docs/kernels.md, "Testing a kernel alone"): feed its inputs, step it, read its outputs.

#include <chrono>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "oscar/kernel_instance.hpp"

namespace oscar {

class KernelHarness {
 public:
  /// Builds a kernel of a registered (or loadable) type.
  /// @throws like KernelInstance, or std::runtime_error for an unknown type.
  explicit KernelHarness(const std::string& type, YAML::Node params = {},
                         std::string name = "kernel_under_test",
                         std::map<std::string, InputOverrides> input_options = {});
  ~KernelHarness();

  /// Gives a cue to an input, as a producer would (stamped with the harness time if unstamped).
  /// Pull and prefetch inputs are answered from everything fed so far.
  /// A raw input (KernelSetup::raw_input) gets the cue serialized, as from a producer of type T.
  template <CueType T>
  void feed(const std::string& input, T cue) {
    auto& port = input_port(input);
    const auto& type = cue_type_info<T>();
    if (!port.takes_any_type() && port.type().name != type.name) {
      throw std::invalid_argument("harness: input '" + input + "' takes " + port.type().name +
                                  ", not " + type.name);
    }
    using Form = CueHeaderForm<std::remove_cvref_t<decltype(cue.header())>>;
    if (Form::stamp_count(cue.header()) == 0) append_stamp(cue.header(), now_);
    feed_erased(port, type, std::make_shared<const T>(std::move(cue)));
  }

  /// Runs process() once at the harness time.
  void step() { instance_->run(now_, Trigger::kHarness, false); }
  /// Runs stub() once.
  void step_stub() { instance_->run(now_, Trigger::kHarness, true); }

  /// Sends a command to the kernel as a module's frame delivers one (docs/kernels.md, "Command
  /// ports"): CDR-encoded, checked against the declared command, decoded, and handed to the
  /// kernel's handler now, between steps. The harness has no modes: the kernel always takes it.
  /// @throws std::invalid_argument as a module refuses the command (no such command, another
  ///         request type, a payload that does not decode).
  template <IdlStruct T>
  CommandAnswer command(const std::string& name, const T& request) {
    const auto& type = idl_type_info<T>();
    return command_cdr(name, type.name, type.serialize(&request));
  }
  /// The same with the request as it travels: CDR bytes the sender says are a `type`.
  CommandAnswer command_cdr(const std::string& name, const std::string& type,
                            const std::vector<std::uint8_t>& cdr);

  /// Every cue the output published since the last call, oldest first.
  template <CueType T>
  std::vector<std::shared_ptr<const T>> take(const std::string& output) {
    std::vector<std::shared_ptr<const T>> out;
    for (auto& cue : take_erased(output)) out.push_back(std::static_pointer_cast<const T>(cue));
    return out;
  }

  /// How many cues the output published since the last take (and takes them).
  std::size_t take_count(const std::string& output) { return take_erased(output).size(); }

  /// A resource wish the kernel declares: whether it asks for it now (Wish::asked()).
  /// @throws std::invalid_argument if it declares no wish of that name.
  const Wish& wish(const std::string& name) const;

  Stamp now() const { return now_; }
  void set_now(Stamp t) { now_ = t; }
  void advance(std::chrono::nanoseconds d) { now_ += d.count(); }

  KernelInstance& instance() { return *instance_; }
  Kernel& kernel() { return instance_->kernel(); }

 private:
  struct Captured;
  InputPort& input_port(const std::string& name);
  void feed_erased(InputPort& port, const CueTypeInfo& type, std::shared_ptr<const void> cue);
  std::vector<std::shared_ptr<const void>> take_erased(const std::string& output);

  Stamp now_ = 1'000'000'000;  // 1 s after the epoch: stamps are never 0 ("none")
  std::unique_ptr<KernelInstance> instance_;
  std::map<std::string, std::unique_ptr<Captured>> captured_;    // per output
  std::map<std::string, std::unique_ptr<RingBuffer>> produced_;  // per input: what was fed
};

}  // namespace oscar
