// oscar-applet: a process of applets (docs/coordinator.md, "Applets in other processes"). Boot
// starts it, through the registry and a monitor, for every `process:` of the coordinator:
// section's applets, as a module of that name (so the registry supervises and restarts it like
// any module); next to the module frame it runs the applets of that process in an AppletHost,
// talking to the coordinator over DDS. With --applets FILE it also runs applets the system file
// does not configure, which join the running system by their hello (docs/coordinator.md,
// "Adding and removing at run time"); without a process of the file's it runs them alone, not
// supervised by the registry.
#include <csignal>
#include <cstdio>
#include <thread>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/applets/config.hpp"
#include "oscar/coordinator/applet_host.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/kernel.hpp"
#include "oscar/kernel_registry.hpp"
#include "oscar/module.hpp"
#include "oscar/network.hpp"
#include "oscar/process_util.hpp"
#include "oscar/security_files.hpp"

namespace oscar::coordinator {
namespace {

/// The kernel of a process of applets: its module's frame announces the process to the
/// registry and beats. The applets run beside it.
class AppletHostKernel final : public Kernel {
 public:
  explicit AppletHostKernel(KernelSetup& /*setup*/) {}
  void process(Cycle& /*cycle*/) override {}
  void stub(Cycle& /*cycle*/) override {}
};

}  // namespace
}  // namespace oscar::coordinator

OSCAR_REGISTER_KERNEL(oscar::coordinator::AppletHostKernel, "applet_host")

int main(int argc, char** argv) {
  CLI::App app{"oscar-applet: a process running applets of a system against its coordinator"};
  std::string file, module_name, restore, joining_file;
  int domain = -1;
  unsigned incarnation = 1;
  bool suspended = false;
  app.add_option("file", file, "the system file")->required();
  app.add_option("--module", module_name,
                 "the process's name (an applet's process:; with --applets alone: the name the "
                 "coordinator shows, default 'joined')");
  app.add_option("--applets", joining_file,
                 "YAML with applets: (entries as in coordinator: applets:) that join the running "
                 "system: the coordinator adds them at their first hello");
  app.add_option("--incarnation", incarnation, "which start of the process this is")
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
    YAML::Node joining;
    if (!joining_file.empty()) {
      joining =
          oscar::applets::parse_yaml(oscar::applets::read_text_file(joining_file), joining_file);
      if (module_name.empty()) module_name = "joined";
    }
    if (module_name.empty()) throw std::invalid_argument("--module or --applets is required");
    const auto* m = system.find_module(module_name);
    const auto applets = oscar::coordinator::AppletHost::applets_of(system, module_name);
    if (!joining_file.empty() && (!m || m->program != "oscar-applet")) {
      // Joining applets alone: no module frame (the registry does not know this process).
      if (!system.coordinator) throw std::invalid_argument(file + ": no coordinator: section");
      const auto* coordinator = system.find_module(oscar::SystemSpec::kCoordinatorModule);
      const auto plugin_path =
          oscar::with_plugins(coordinator ? coordinator->spec.plugins : std::vector<std::string>{},
                              oscar::plugin_search_path());
      oscar::DdsParticipant participant(
          system.domain, "oscar:applets:" + module_name,
          system.network_for(system.coordinator->host,
                             oscar::security_files::module_identity(module_name)));
      oscar::coordinator::AppletHost host(system, participant, {}, joining, joining_file,
                                          module_name, plugin_path);
      host.start();
      int sig = 0;
      sigwait(&signals, &sig);
      host.stop();
      return 0;
    }
    if (!m || m->program != "oscar-applet" || applets.empty()) {
      throw std::invalid_argument(file + ": no applet runs in process '" + module_name +
                                  "' (an applet's process: in the coordinator: section)");
    }
    auto spec = m->spec;
    spec.incarnation = incarnation;
    spec.start_suspended = suspended;
    if (!restore.empty()) spec.restore(YAML::Load(restore));
    const auto plugin_path = oscar::with_plugins(spec.plugins, oscar::plugin_search_path());
    oscar::Module module(spec, plugin_path);
    oscar::DdsParticipant participant(system.domain, "oscar:applets:" + module_name, spec.network);
    oscar::coordinator::AppletHost host(system, participant, applets, joining, joining_file,
                                        module_name, plugin_path);
    // The applets' log goes where the module's goes: stdout and oscar/log (boot shows it).
    auto previous_logger = spdlog::default_logger();
    spdlog::set_default_logger(
        std::make_shared<spdlog::logger>(module.kernel(spec.kernels.front().name).log()));
    module.start(system.domain);
    host.start();
    std::thread signal_waiter([&] {
      int sig = 0;
      sigwait(&signals, &sig);
      module.request_stop();
    });
    module.wait();
    host.stop();
    spdlog::set_default_logger(previous_logger);  // before the module's log sink goes
    module.stop();
    pthread_kill(signal_waiter.native_handle(), SIGTERM);
    signal_waiter.join();
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-applet: %s\n", e.what());
    return 2;
  }
}
