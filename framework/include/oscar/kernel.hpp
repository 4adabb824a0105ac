#pragma once
/// @file The kernel API (docs/kernels.md): what a module author
/// writes.

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <type_traits>

#include <fmt/format.h>
#include <spdlog/logger.h>
#include <yaml-cpp/yaml.h>

#include "oscar/command.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/input.hpp"
#include "oscar/output.hpp"
#include "oscar/params.hpp"
#include "oscar/raw_cue.hpp"
#include "oscar/time.hpp"
#include "oscar/wish.hpp"

namespace oscar {

/// Why a kernel runs this cycle.
enum class Trigger { kCycle, kInput, kCommand, kModule, kHarness };

/// One run of a kernel: its time and its logger. process() takes everything it needs from here,
/// from its inputs and from its own state; it does not read the wall clock or sleep.
class Cycle {
 public:
  Cycle(Stamp now, std::uint64_t index, Trigger trigger, spdlog::logger& log)
      : now_(now), index_(index), trigger_(trigger), log_(log) {}
  /// The time this cycle started (ns since the epoch).
  Stamp now() const { return now_; }
  /// 1 for the first cycle of this kernel, then 2, 3, ...
  std::uint64_t index() const { return index_; }
  Trigger trigger() const { return trigger_; }
  spdlog::logger& log() const { return log_; }

 private:
  Stamp now_;
  std::uint64_t index_;
  Trigger trigger_;
  spdlog::logger& log_;
};

/// The base of every kernel. Constructors only declare ports and parameters (no DDS, threads,
/// files or devices): devices open in on_activate(). A kernel reads its parameters and never
/// writes them: the frame owns them and reads them from other threads.
class Kernel {
 public:
  virtual ~Kernel() = default;
  /// One processing cycle.
  virtual void process(Cycle& cycle) = 0;
  /// Stub mode: plausible outputs without the algorithm, so neighbours can be tested alone.
  virtual void stub(Cycle& cycle) = 0;
  /// Called on the processing thread before the first cycle after activation.
  virtual void on_activate() {}
  /// Called on the processing thread after the last cycle before deactivation.
  virtual void on_deactivate() {}
  /// Called on the processing thread after set_param changed a parameter.
  virtual void on_params_changed() {}
};

/// What the framework builds for one kernel: its ports, parameters and command ports, in
/// declaration order.
struct KernelPorts {
  explicit KernelPorts(const std::string& kernel) : params(fmt::format("kernel '{}'", kernel)) {}
  std::deque<std::unique_ptr<InputPort>> inputs;
  std::deque<std::unique_ptr<OutputPort>> outputs;
  ParamSpec params;
  std::deque<std::unique_ptr<CommandPort>> commands;
  std::deque<std::unique_ptr<Wish>> wishes;
  InputPort* find_input(std::string_view name) const;
  OutputPort* find_output(std::string_view name) const;
  CommandPort* find_command(std::string_view name) const;
};

/// Handed to a kernel's constructor: declares ports and parameters and returns typed handles.
class KernelSetup {
 public:
  /// `params` holds the configured values (YAML map); `input_options` what the configuration
  /// sets per input name.
  KernelSetup(std::string kernel_name, std::string kernel_type, KernelPorts& ports,
              YAML::Node params = {}, std::map<std::string, InputOverrides> input_options = {});

  const std::string& kernel_name() const { return name_; }
  const std::string& kernel_type() const { return type_; }

  /// Declares an input. Each option the configuration names for this input (YAML `depth:`,
  /// `transfer:`) replaces the one in `defaults`; the others, and the reliability, stand.
  /// @throws std::invalid_argument if the name is taken or not an identifier.
  template <CueType T>
  Input<T>& input(const std::string& name, InputOptions defaults = {}) {
    check_port_name(name);
    auto options = defaults;
    if (auto it = input_options_.find(name); it != input_options_.end()) {
      options = it->second.applied_to(defaults);
    }
    auto port = std::make_unique<Input<T>>(name_, name, cue_type_info<T>(), options);
    auto& ref = *port;
    ports_.inputs.push_back(std::move(port));
    return ref;
  }

  /// Declares an input that takes cues of any type, as RawCue: the producer's type name, the cue
  /// serialized, its header. The type is the producer's, found when the input is wired (from its
  /// output in process, from discovery across processes); each cue is kept as the wire has it.
  /// For kernels that handle cues without their types (the logger); push transfer only.
  /// @throws std::invalid_argument if the name is taken or not an identifier, or if the defaults
  ///         or the configuration ask for pull or prefetch.
  Input<RawCue>& raw_input(const std::string& name, InputOptions defaults = {});

  /// The inputs the configuration names for this kernel (the keys of its `inputs:`), sorted:
  /// what a kernel declares whose inputs are the configuration's choice (the logger).
  std::vector<std::string> configured_inputs() const;

  /// Declares an output. @throws std::invalid_argument if the name is taken.
  template <CueType T>
  Output<T>& output(const std::string& name, OutputOptions options = {}) {
    check_port_name(name);
    auto port = std::make_unique<Output<T>>(name_, name, cue_type_info<T>(), options);
    auto& ref = *port;
    ports_.outputs.push_back(std::move(port));
    return ref;
  }

  /// Declares a command port (docs/kernels.md, "Command ports"): the kernel accepts commands
  /// `name` whose request is a T (an IDL struct declared with OSCAR_DECLARE_IDL_TYPE). The frame
  /// calls `handler(const T&)` on the processing thread, never during process(), and sends its
  /// CommandAnswer back to the sender.
  /// @throws std::invalid_argument if the name is taken or not an identifier.
  template <IdlStruct T, class F>
  void command(const std::string& name, F handler) {
    static_assert(std::is_invocable_r_v<CommandAnswer, F&, const T&>,
                  "a command handler is called as handler(const T& request) and returns an "
                  "oscar::CommandAnswer (CommandAnswer::accept() or CommandAnswer::refuse(why))");
    check_command_name(name);
    ports_.commands.push_back(std::make_unique<CommandPort>(
        name_, name, idl_type_info<T>(), [h = std::move(handler)](const void* request) mutable {
          return CommandAnswer(h(*static_cast<const T*>(request)));
        }));
  }

  /// Declares a resource wish (docs/kernels.md, "Resource wishes"): `name` is a bundle the system
  /// file declares for this kernel under `coordinator: wishes:`. The kernel asks for it and
  /// drops it while it runs (Wish::ask, Wish::drop); the coordinator's plan grants it or not.
  /// A kernel's wishes are dropped when it is deactivated, and asked again on activation if the
  /// kernel still asks (it may also drop them itself in on_deactivate()).
  /// @throws std::invalid_argument if the name is taken or not an identifier.
  Wish& wish(const std::string& name);

  /// Binds a Params struct (with `void describe(ParamSpec&)`) and applies the configured values
  /// at once, so the constructor can use them (e.g. to choose an output type).
  /// @throws std::invalid_argument on an unknown parameter or a bad value.
  template <class P>
  void params(P& p) {
    p.describe(ports_.params);
    ports_.params.set_all(params_);
    params_bound_ = true;
  }

  /// True if the configuration names parameters but the kernel bound none (checked by the host).
  bool unbound_params() const;

 private:
  void check_port_name(const std::string& name) const;
  void check_command_name(const std::string& name) const;

  std::string name_, type_;
  KernelPorts& ports_;
  YAML::Node params_;
  std::map<std::string, InputOverrides> input_options_;
  bool params_bound_ = false;
};

namespace internal {
using KernelFactory = std::unique_ptr<Kernel> (*)(KernelSetup&);
/// Registers a kernel type; called by OSCAR_REGISTER_KERNEL at load time. Returns true.
bool register_kernel_type(const char* type, KernelFactory factory, const char* source_file);
template <class K>
std::unique_ptr<Kernel> make_kernel(KernelSetup& setup) {
  return std::make_unique<K>(setup);
}
}  // namespace internal

}  // namespace oscar

#define OSCAR_INTERNAL_CONCAT2(a, b) a##b
#define OSCAR_INTERNAL_CONCAT(a, b) OSCAR_INTERNAL_CONCAT2(a, b)

/// Makes CLASS loadable as kernel type TYPE (one line, in the kernel's .cpp).
#define OSCAR_REGISTER_KERNEL(CLASS, TYPE)                                                  \
  static_assert(std::is_base_of_v<::oscar::Kernel, CLASS>,                                  \
                #CLASS " must derive from oscar::Kernel to be registered");                 \
  static_assert(std::is_constructible_v<CLASS, ::oscar::KernelSetup&>,                      \
                #CLASS " needs a constructor " #CLASS "(oscar::KernelSetup& setup)");       \
  namespace {                                                                               \
  [[maybe_unused]] const bool OSCAR_INTERNAL_CONCAT(oscar_kernel_registered_, __LINE__) =   \
      ::oscar::internal::register_kernel_type(TYPE, &::oscar::internal::make_kernel<CLASS>, \
                                              __FILE__);                                    \
  }
