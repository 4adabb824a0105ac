#include "oscar/kernel_instance.hpp"

#include <stdexcept>

#include <spdlog/sinks/null_sink.h>
#include <spdlog/spdlog.h>

namespace oscar {

KernelInstance::KernelInstance(const KernelTypeInfo& type, std::string name, YAML::Node params,
                               std::map<std::string, InputOverrides> input_options,
                               std::shared_ptr<spdlog::logger> log)
    : name_(std::move(name)),
      type_(type.type),
      ports_(std::make_unique<KernelPorts>(name_)),
      log_(log ? std::move(log) : spdlog::default_logger()) {
  for (const auto& [input, options] : input_options) {
    if (options.depth && *options.depth == 0) {
      throw std::invalid_argument(fmt::format(
          "kernel '{}' ({}): input '{}' has depth 0; a ring buffer holds at least 1 cue", name_,
          type_, input));
    }
  }
  KernelSetup setup(name_, type_, *ports_, params, input_options);
  kernel_ = type.make(setup);
  if (setup.unbound_params()) {
    throw std::invalid_argument(fmt::format(
        "kernel '{}' ({}) has no parameters, but the configuration gives some", name_, type_));
  }
  for (const auto& [input, options] : input_options) {
    if (!ports_->find_input(input)) {
      std::string known;
      for (const auto& p : ports_->inputs) known += (known.empty() ? "" : ", ") + p->name();
      throw std::invalid_argument(fmt::format("kernel '{}' ({}) has no input '{}'; its inputs: {}",
                                              name_, type_, input,
                                              known.empty() ? "(none)" : known));
    }
  }
}

CommandPort& KernelInstance::command(const std::string& name) {
  if (auto* port = ports_->find_command(name)) return *port;
  if (ports_->commands.empty()) {
    throw std::invalid_argument(fmt::format(
        "kernel '{}' ({}) has no command '{}': it declares no commands", name_, type_, name));
  }
  std::string known;
  for (const auto& c : ports_->commands) {
    known += fmt::format("{}{} ({})", known.empty() ? "" : ", ", c->name(), c->type().name);
  }
  throw std::invalid_argument(fmt::format("kernel '{}' ({}) has no command '{}'; its commands: {}",
                                          name_, type_, name, known));
}

void KernelInstance::run(Stamp now, Trigger trigger, bool stub) {
  Cycle cycle(now, ++cycles_, trigger, *log_);
  if (stub) {
    kernel_->stub(cycle);
  } else {
    kernel_->process(cycle);
  }
}

}  // namespace oscar
