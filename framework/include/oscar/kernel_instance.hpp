#pragma once
/// @file One constructed kernel with its ports, parameters and logger.

#include <atomic>
#include <map>
#include <memory>
#include <string>

#include "oscar/kernel.hpp"
#include "oscar/kernel_registry.hpp"

namespace oscar {

class KernelInstance {
 public:
  /// Constructs the kernel. @throws std::invalid_argument for bad parameters or port
  /// declarations, naming the kernel, its type and the rule.
  KernelInstance(const KernelTypeInfo& type, std::string name, YAML::Node params = {},
                 std::map<std::string, InputOverrides> input_options = {},
                 std::shared_ptr<spdlog::logger> log = nullptr);

  const std::string& name() const { return name_; }
  const std::string& type() const { return type_; }
  Kernel& kernel() { return *kernel_; }
  KernelPorts& ports() { return *ports_; }
  const KernelPorts& ports() const { return *ports_; }
  spdlog::logger& log() { return *log_; }
  std::uint64_t cycles() const { return cycles_; }

  /// The command port `name`.
  /// @throws std::invalid_argument naming the kernel's commands (or saying it declares none).
  CommandPort& command(const std::string& name);

  /// Runs process() (or stub() in stub mode) once.
  void run(Stamp now, Trigger trigger, bool stub);

 private:
  std::string name_, type_;
  std::unique_ptr<KernelPorts> ports_;  // declared before kernel_: the kernel holds references
  std::shared_ptr<spdlog::logger> log_;
  std::unique_ptr<Kernel> kernel_;
  std::atomic<std::uint64_t> cycles_{0};
};

}  // namespace oscar
