// oscar restart MODULE / oscar shutdown: ask the registry (one program, two names).
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/system_options.hpp"

int main(int argc, char** argv) {
  const bool restart = std::filesystem::path(argv[0]).filename() == "oscar-restart";
  CLI::App app{restart ? "oscar restart: restarts a module (also one given up or on manual policy)"
                       : "oscar shutdown: stops the system in order"};
  std::string module;
  oscar::SystemOptions tool;
  if (restart) app.add_option("module", module, "the module to restart")->required();
  tool.add_to(app);
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    auto participant = tool.participant(argv[0], oscar::ToolAuthority::kActAsBoot);
    oscar::RegistryClient client(*participant, "operator");
    client.request(restart ? oscar::REG_RESTART : oscar::REG_SHUTDOWN, module);
    std::printf(restart ? "restarting %s\n" : "shutting down%s\n", module.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar %s: %s\n", restart ? "restart" : "shutdown", e.what());
    return 2;
  }
}
