#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "oscar/input.hpp"
#include "oscar/output.hpp"
#include "oscar/raw_cue.hpp"

namespace oscar {

const char* to_string(Transfer t) {
  switch (t) {
    case Transfer::kPush:
      return "push";
    case Transfer::kPull:
      return "pull";
    case Transfer::kPrefetch:
      return "prefetch";
  }
  return "?";
}

Transfer parse_transfer(std::string_view text) {
  if (text == "push") return Transfer::kPush;
  if (text == "pull") return Transfer::kPull;
  if (text == "prefetch") return Transfer::kPrefetch;
  throw std::invalid_argument(fmt::format("transfer '{}': expected push, pull or prefetch", text));
}

InputPort::InputPort(std::string kernel, std::string name, const CueTypeInfo& type,
                     InputOptions options)
    : kernel_(std::move(kernel)),
      name_(std::move(name)),
      type_(type),
      transfer_(options.transfer),
      reliability_(options.reliability),
      takes_any_type_(&type == &raw_cue_type()),
      buffer_(options.depth) {}

bool InputPort::takes_any_type() const { return takes_any_type_; }

void InputPort::deliver_from(const CueTypeInfo& producer, std::shared_ptr<const void> cue) {
  const Stamp generated = producer.header.generation_stamp(cue.get());
  deliver_from(producer, std::move(cue), generated);
}

void InputPort::deliver_from(const CueTypeInfo& producer, std::shared_ptr<const void> cue,
                             Stamp generated) {
  if (takes_any_type_ && &producer != &type_) cue = to_raw_cue(producer, cue.get());
  buffer_.push(std::move(cue), generated, wall_now());
  std::shared_ptr<const std::function<void()>> hook;
  {
    std::lock_guard lock(hooks_mutex_);
    hook = arrival_hook_;
  }
  if (hook) (*hook)();
}

void InputPort::set_arrival_hook(std::function<void()> hook) {
  auto shared = hook ? std::make_shared<const std::function<void()>>(std::move(hook)) : nullptr;
  std::lock_guard lock(hooks_mutex_);
  arrival_hook_ = std::move(shared);
}

void InputPort::set_pull_source(std::shared_ptr<PullSource> source) {
  std::lock_guard lock(hooks_mutex_);
  pull_source_ = std::move(source);
}

std::shared_ptr<PullSource> InputPort::pull_source() {
  std::shared_ptr<PullSource> source;
  {
    std::lock_guard lock(hooks_mutex_);
    source = pull_source_;
  }
  if (!source) {
    throw std::logic_error(fmt::format(
        "input '{}/{}' cannot pull: it is not connected to a producer", kernel_, name_));
  }
  return source;
}

std::shared_future<std::shared_ptr<const void>> InputPort::request(PullQuery query, Stamp t,
                                                                   std::chrono::nanoseconds wait) {
  if (wait < std::chrono::nanoseconds::zero() || wait > kMaxPullWait) {
    throw std::invalid_argument(fmt::format(
        "input '{}/{}': a pull may ask the producer to wait 0 to {} s, not {} ms", kernel_, name_,
        kMaxPullWait.count(), std::chrono::duration<double, std::milli>(wait).count()));
  }
  return pull_source()->request(query, t, wait);
}

std::shared_future<CueBlock> InputPort::request(const PullBlock& block) {
  if (block.kind == PullBlock::Kind::kRange) check_time_range(block.t0, block.t1);
  return pull_source()->request(block);
}

OutputPort::OutputPort(std::string kernel, std::string name, const CueTypeInfo& type,
                       OutputOptions options)
    : kernel_(std::move(kernel)),
      name_(std::move(name)),
      type_(type),
      options_(options),
      buffer_(options.depth),
      clock_(&wall_now) {
  // Checked now, where the address is known: the header's source holds it on every cue.
  if (address().size() > type_.header.max_source_length) {
    throw std::invalid_argument(fmt::format(
        "output '{}' ({}): its address has {} characters, but a {} cue's header holds a source "
        "of at most {}; shorten the kernel's or the output's name",
        address(), type_.name, address().size(), type_.name, type_.header.max_source_length));
  }
}

void OutputPort::publish_erased(std::shared_ptr<void> cue) {
  std::lock_guard lock(mutex_);
  // The oldest cue leaves the ring before this one is stamped: freeing it (a chunk goes back to
  // RouDi) is no part of this cue's journey. What follows the publish counts as well, for a
  // consumer woken on this core runs only once this thread waits; it is kept short.
  buffer_.drop_oldest_if_full();
  const Stamp generated = type_.header.complete(cue.get(), ++seq_, address(), clock_);
  if (persisted_seq_) *persisted_seq_ = seq_;
  std::shared_ptr<const void> frozen = std::move(cue);
  if (chunks_) frozen = chunks_->publish(std::move(frozen));
  hand_over(frozen, generated);
}

void OutputPort::forward_erased(std::shared_ptr<const void> cue) {
  std::lock_guard lock(mutex_);
  buffer_.drop_oldest_if_full();
  const Stamp generated = type_.header.generation_stamp(cue.get());
  if (chunks_) cue = chunks_->publish(std::move(cue));
  hand_over(cue, generated);
}

// After the stamp every step counts toward the cue's latency, on a cold cache after a large cue
// was written: the generation stamp is passed along, not read back from the header.
void OutputPort::hand_over(const std::shared_ptr<const void>& cue, Stamp generated) {
  buffer_.push(cue, generated, wall_now());
  for (auto* input : consumers_) input->deliver_from(type_, cue, generated);
  if (remote_) remote_(cue.get());
}

void OutputPort::connect(InputPort* input) {
  check_types(*input, address(), type_);
  // In process every cue arrives anyway; refused all the same, so a module file means the same
  // whether its kernels share a process or not.
  check_reliability(*input, address(), options_);
  std::lock_guard lock(mutex_);
  if (std::find(consumers_.begin(), consumers_.end(), input) == consumers_.end()) {
    consumers_.push_back(input);
  }
}

void check_types(const InputPort& input, const std::string& source, const CueTypeInfo& type) {
  if (input.takes_any_type() || input.type().name == type.name) return;
  throw std::invalid_argument(
      fmt::format("cannot wire {} ({}) to input {}/{} ({}): the types differ", source, type.name,
                  input.kernel(), input.name(), input.type().name));
}

void check_reliability(const InputPort& input, const std::string& source,
                       const OutputOptions& declared) {
  if (input.reliability() != Reliability::kReliable || declared.reliable) return;
  throw std::invalid_argument(fmt::format(
      "input '{}.{}' (reliable) is wired to '{}', which is best effort: a reliable reader never "
      "matches a best-effort writer; declare the input best effort or make the output reliable",
      input.kernel(), input.name(), source));
}

void OutputPort::disconnect(InputPort* input) {
  std::lock_guard lock(mutex_);
  std::erase(consumers_, input);
}

void OutputPort::set_remote(std::function<void(const void*)> remote) {
  std::lock_guard lock(mutex_);
  remote_ = std::move(remote);
}

void OutputPort::set_chunks(std::shared_ptr<CueChunks> chunks) {
  std::lock_guard lock(mutex_);
  chunks_ = std::move(chunks);
}

std::shared_ptr<void> OutputPort::loan_erased() {
  std::shared_ptr<CueChunks> chunks;
  {
    std::lock_guard lock(mutex_);
    chunks = chunks_;
  }
  if (chunks) {
    if (auto cue = chunks->loan()) return cue;
  }
  return type_.make();
}

void OutputPort::persist_sequence(std::uint64_t* counter) {
  std::lock_guard lock(mutex_);
  persisted_seq_ = counter;
  seq_ = std::max(seq_, *counter);
}

void OutputPort::set_clock(std::function<Stamp()> clock) {
  std::lock_guard lock(mutex_);
  clock_ = std::move(clock);
}

}  // namespace oscar
