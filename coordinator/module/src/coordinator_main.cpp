// oscar-coordinator: the coordinator process (docs/coordinator.md). Boot starts it, through the
// registry and a monitor, from the system file's coordinator: section, as a module named
// "coordinator" (so the registry supervises and restarts it like any module); next to the module
// frame it runs the Coordinator.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/coordinator/coordinator.hpp"
#include "oscar/coordinator/plan_json.hpp"
#include "oscar/coordinator/swarm_service.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/kernel.hpp"
#include "oscar/kernel_registry.hpp"
#include "oscar/module.hpp"
#include "oscar/network.hpp"
#include "oscar/process_util.hpp"

#include <spdlog/spdlog.h>

namespace oscar::coordinator {
namespace {

// Set once the coordinator exists (the kernel is made before it, by the module).
std::atomic<Coordinator*> the_coordinator{nullptr};

/// The coordinator's kernel: its module's frame announces the process to the registry, beats,
/// and takes commands; the command port `applet` passes an operator's event to an applet's
/// bundle. The work is the Coordinator's, beside it.
class CoordinatorKernel final : public Kernel {
 public:
  explicit CoordinatorKernel(KernelSetup& setup) {
    setup.command<AppletEvent>("applet", [](const AppletEvent& e) {
      auto* c = the_coordinator.load();
      if (!c) return CommandAnswer::refuse("the coordinator is starting");
      if (const auto error = c->apply_event(e)) {
        return CommandAnswer::refuse(*error);
      }
      if (e.event() == "add") return CommandAnswer::accept("added");
      if (e.event() == "remove") {
        return CommandAnswer::accept(e.service().empty() ? "removed applet " + e.applet()
                                                         : "removed service " + e.service());
      }
      return CommandAnswer::accept(e.applet() + "/" + e.bundle() + ": " + e.event());
    });
  }
  void process(Cycle& /*cycle*/) override {}
  void stub(Cycle& /*cycle*/) override {}
};

}  // namespace
}  // namespace oscar::coordinator

OSCAR_REGISTER_KERNEL(oscar::coordinator::CoordinatorKernel, "coordinator")

int main(int argc, char** argv) {
  CLI::App app{"oscar-coordinator: the coordinator of a system (services, applets)"};
  std::string file, module_name = oscar::SystemSpec::kCoordinatorModule, restore;
  int domain = -1;
  unsigned incarnation = 1;
  bool suspended = false;
  app.add_option("file", file, "the system file")->required();
  app.add_option("--module", module_name, "the coordinator's module name (the registry's)");
  app.add_option("--incarnation", incarnation, "which start of the coordinator this is")
      ->check(CLI::PositiveNumber);
  app.add_option("-d,--domain", domain, "DDS domain (default: the file's)");
  app.add_option("--restore", restore, "the configuration the registry gives a restarted module");
  app.add_flag("--suspended", suspended, "start suspended (the registry resumes it)");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);

  auto signals = oscar::block_stop_signals();
  oscar::keep_cue_memory_in_process();
  try {
    oscar::register_standard_cue_types();
    auto system = oscar::SystemSpec::load(file);
    if (domain >= 0) system.override_domain(domain);
    const auto* m = system.find_module(module_name);
    if (!m || !system.coordinator) {
      throw std::invalid_argument(file + ": no coordinator: section");
    }
    auto spec = m->spec;
    spec.incarnation = incarnation;
    spec.start_suspended = suspended;
    if (!restore.empty()) spec.restore(YAML::Load(restore));
    const auto plugin_path = oscar::with_plugins(spec.plugins, oscar::plugin_search_path());
    oscar::Module module(spec, plugin_path);
    oscar::DdsParticipant participant(system.domain, "oscar:coordinator-plan", spec.network);
    oscar::coordinator::Coordinator coordinator(system, participant, plugin_path);
    std::unique_ptr<oscar::coordinator::SwarmService> swarm;
    if (auto setup = oscar::coordinator::SwarmSetup::from(system)) {
      swarm = std::make_unique<oscar::coordinator::SwarmService>(std::move(*setup), participant);
    }
    // The coordinator's log goes where its module's goes: stdout and oscar/log (boot shows it).
    auto previous_logger = spdlog::default_logger();
    spdlog::set_default_logger(
        std::make_shared<spdlog::logger>(module.kernel(spec.kernels.front().name).log()));
    oscar::coordinator::the_coordinator = &coordinator;
    module.start(system.domain);
    coordinator.start();
    if (swarm) swarm->start();
    std::thread signal_waiter([&] {
      int sig = 0;
      sigwait(&signals, &sig);
      module.request_stop();
    });
    module.wait();
    if (swarm) swarm->stop();
    coordinator.stop();
    oscar::coordinator::the_coordinator = nullptr;
    spdlog::set_default_logger(previous_logger);  // before the module's log sink goes
    module.stop();
    pthread_kill(signal_waiter.native_handle(), SIGTERM);
    signal_waiter.join();
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-coordinator: %s\n", e.what());
    return 2;
  }
}
