// oscar-run: hosts one or more kernels from plugins in one process (docs/architecture.md).
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/cue_types.hpp"
#include "oscar/module.hpp"
#include "oscar/process_util.hpp"
#include "oscar/security_files.hpp"
#include "oscar/time.hpp"

namespace {

oscar::ModuleSpec spec_from_flags(const std::string& name, const std::vector<std::string>& kernels,
                                  const std::vector<std::string>& params,
                                  const std::vector<std::string>& inputs) {
  YAML::Node root;
  root["name"] = name;
  for (const auto& k : kernels) {
    const auto colon = k.find(':');
    YAML::Node kernel;
    kernel["type"] = k.substr(0, colon);
    kernel["name"] = colon == std::string::npos ? k : k.substr(colon + 1);
    root["kernels"].push_back(kernel);
  }
  const auto kernel_node = [&](const std::string& flag, const std::string& text) {
    const auto dot = text.find('.');
    const auto eq = text.find('=');
    if (dot == std::string::npos || eq == std::string::npos || eq < dot) {
      throw std::invalid_argument(fmt::format("{} '{}': expected KERNEL.KEY=VALUE", flag, text));
    }
    const auto kernel = text.substr(0, dot);
    for (auto k : root["kernels"]) {
      if (k["name"].as<std::string>() == kernel) {
        return std::make_tuple(k, text.substr(dot + 1, eq - dot - 1), text.substr(eq + 1));
      }
    }
    throw std::invalid_argument(fmt::format("{} '{}': no kernel named '{}'", flag, text, kernel));
  };
  for (const auto& p : params) {
    auto [k, key, value] = kernel_node("--param", p);
    k["params"][key] = YAML::Load(value);
  }
  for (const auto& i : inputs) {
    auto [k, key, value] = kernel_node("--input", i);
    k["inputs"][key] = value;
  }
  return oscar::ModuleSpec::from_yaml(root, "<command line>");
}

}  // namespace

namespace oscar {
int run_main(int argc, char** argv) {
  CLI::App app{"oscar-run: hosts OSCAR kernels in one module process"};
  std::string file, module_name, mode, name = "module";
  std::vector<std::string> kernels, params, inputs, plugins;
  int domain = -1;
  unsigned incarnation = 1;
  bool stub = false, check = false, list = false, modules = false, suspended = false;
  app.add_option("file", file, "module YAML (one module map, or a system file with --module)");
  app.add_option("--module", module_name, "the module of a system file to run");
  app.add_option("--name", name, "module name when kernels are given on the command line");
  app.add_option("-k,--kernel", kernels, "TYPE[:NAME] of a kernel to host (repeatable)");
  app.add_option("-p,--param", params, "KERNEL.KEY=VALUE (repeatable)");
  app.add_option("-i,--input", inputs, "KERNEL.INPUT=SOURCE_KERNEL/CHANNEL (repeatable)");
  app.add_option("-m,--mode", mode,
                 "module mode: continuous:33ms | single_step[:trigger] | deactivated");
  app.add_option("-d,--domain", domain, "DDS domain (default: the file's, $OSCAR_DOMAIN, or 0)");
  app.add_option("--plugin", plugins, "plugin file to load first (repeatable)");
  app.add_flag("--stub", stub, "start every kernel in stub mode");
  app.add_option("--incarnation", incarnation, "which start of this module this is (registry)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--suspended", suspended, "start suspended (the registry resumes it)");
  std::string restore;
  app.add_option("--restore", restore,
                 "YAML {kernel: {mode, stub, params, inputs}}: the configuration a restarted "
                 "module gets back (the registry passes it)");
  app.add_flag("--check", check, "load and check the module, print it, and exit");
  app.add_flag("--list-types", list, "list the kernel types that can be loaded and exit");
  app.add_flag("--list-modules", modules, "list the modules of the system file and exit");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);

  auto signals = block_stop_signals();  // every thread started from here inherits it
  keep_cue_memory_in_process();

  try {
    register_standard_cue_types();
    for (const auto& p : plugins) load_plugin(p);
    if (list) {
      for (const auto& t : available_kernel_types(plugin_search_path())) std::cout << t << "\n";
      return 0;
    }
    if (modules) {
      const auto root = load_yaml_file(file);
      for (const auto& m : root["modules"]) std::cout << m["name"].as<std::string>() << "\n";
      return 0;
    }
    if (file.empty() == kernels.empty()) {
      throw std::invalid_argument("give either a module YAML file or --kernel TYPE[:NAME]");
    }
    auto spec = file.empty() ? spec_from_flags(name, kernels, params, inputs)
                             : ModuleSpec::load(file, module_name);
    if (!mode.empty()) spec.mode = ModeSpec::parse_text(mode);
    if (stub) spec.stub = true;
    spec.incarnation = incarnation;
    if (!restore.empty()) spec.restore(YAML::Load(restore));
    spec.start_suspended = suspended;
    if (const auto keystore = security_files::keystore_from_env();
        !keystore.empty() && !spec.network.security) {
      // A module of no system file joins a secured system as the module of its name.
      spec.network.security =
          ParticipantSecurity{keystore, security_files::module_identity(spec.name)};
    }
    Module module(std::move(spec), plugin_search_path());
    if (check) {
      const auto state = module.state();  // kept: a range-for would not extend its life
      for (const auto& k : state.kernels()) {
        std::cout << k.name() << " (" << k.type() << "): " << k.mode() << "\n";
      }
      return 0;
    }
    const int d = domain >= 0 ? domain : module.spec().domain.value_or(domain_from_env(0));
    // The module's domain for what in this process reads it from the environment
    // (domain_from_env).
    setenv("OSCAR_DOMAIN", std::to_string(d).c_str(), 1);
    module.start(d);
    std::thread signal_waiter([&] {
      int sig = 0;
      sigwait(&signals, &sig);
      module.request_stop();
    });
    module.wait();
    module.stop();
    // Wake the signal waiter if the module stopped on a shutdown command.
    pthread_kill(signal_waiter.native_handle(), SIGTERM);
    signal_waiter.join();
    if (const auto reason = module.exit_reason(); !reason.empty()) {
      std::fprintf(stderr, "oscar-run: module '%s' stopped: %s\n", module.spec().name.c_str(),
                   reason.c_str());
      return kKernelFailureExit;
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-run: %s\n", e.what());
    return 2;
  }
}
}  // namespace oscar
