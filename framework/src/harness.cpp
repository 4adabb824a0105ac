#include "oscar/harness.hpp"

#include "ring_pull_source.hpp"

namespace oscar {

struct KernelHarness::Captured {
  std::uint64_t taken = 0;
  // Records what the output publishes, in publishing order.
  struct Sink final : InputPort {
    using InputPort::InputPort;
  };
  std::unique_ptr<Sink> sink;
};

KernelHarness::KernelHarness(const std::string& type, YAML::Node params, std::string name,
                             std::map<std::string, InputOverrides> input_options)
    : instance_(std::make_unique<KernelInstance>(load_kernel_type(type, plugin_search_path()),
                                                 std::move(name), std::move(params),
                                                 std::move(input_options))) {
  auto& ports = instance_->ports();
  for (auto& out : ports.outputs) {
    out->set_clock([this] { return now_; });
    auto c = std::make_unique<Captured>();
    c->sink = std::make_unique<Captured::Sink>("harness", out->name(), out->type(),
                                               InputOptions{.depth = 4096});
    out->connect(c->sink.get());
    captured_[out->name()] = std::move(c);
  }
  for (auto& in : ports.inputs) {
    auto ring = std::make_unique<RingBuffer>(4096);
    in->set_pull_source(std::make_shared<internal::RingPullSource>(*ring, *in));
    produced_[in->name()] = std::move(ring);
  }
}

KernelHarness::~KernelHarness() {
  for (auto& out : instance_->ports().outputs) {
    if (auto it = captured_.find(out->name()); it != captured_.end()) {
      out->disconnect(it->second->sink.get());
    }
  }
}

const Wish& KernelHarness::wish(const std::string& name) const {
  for (const auto& w : instance_->ports().wishes) {
    if (w->name() == name) return *w;
  }
  throw std::invalid_argument("harness: kernel '" + instance_->name() + "' declares no wish '" +
                              name + "'");
}

InputPort& KernelHarness::input_port(const std::string& name) {
  auto* port = instance_->ports().find_input(name);
  if (!port) {
    throw std::invalid_argument("harness: kernel '" + instance_->name() + "' has no input '" +
                                name + "'");
  }
  return *port;
}

void KernelHarness::feed_erased(InputPort& port, const CueTypeInfo& type,
                                std::shared_ptr<const void> cue) {
  produced_.at(port.name())->push(cue, type.header.generation_stamp(cue.get()), now_);
  if (port.transfer() == Transfer::kPush) port.deliver_from(type, std::move(cue));
}

CommandAnswer KernelHarness::command_cdr(const std::string& name, const std::string& type,
                                         const std::vector<std::uint8_t>& cdr) {
  const auto& port = instance_->command(name);
  const auto request = port.decode(type, cdr);
  return port.call(request.get());
}

std::vector<std::shared_ptr<const void>> KernelHarness::take_erased(const std::string& output) {
  const auto it = captured_.find(output);
  if (it == captured_.end()) {
    throw std::invalid_argument("harness: kernel '" + instance_->name() + "' has no output '" +
                                output + "'");
  }
  auto& c = *it->second;
  std::vector<std::shared_ptr<const void>> out;
  for (const auto& e : c.sink->buffer().latest(c.sink->buffer().depth())) {
    if (e.index > c.taken) out.push_back(e.cue);
  }
  c.taken = c.sink->buffer().pushed();
  return out;
}

}  // namespace oscar
