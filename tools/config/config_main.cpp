// oscar config MODULE COMMAND [ARGS...]: sends one configuration command and prints the reply.
#include <cstdio>
#include <iostream>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include <oscar/config_client.hpp>
#include <oscar/registry/registry_client.hpp>
#include <oscar/registry/system_options.hpp>
#include <oscar/time.hpp>

int main(int argc, char** argv) {
  CLI::App app{
      "oscar config: send a configuration command to a module (docs/kernels.md).\n"
      "Commands: activate KERNEL|* [MODE], deactivate KERNEL|*, trigger KERNEL|*,\n"
      "set-cycle KERNEL CYCLE, set-param KERNEL NAME VALUE, rewire KERNEL INPUT SOURCE [WAIT]\n"
      "(WAIT: longest wait for the new source's first cue, default 1s),\n"
      "suspend, resume, stub KERNEL|* on|off, shutdown.\n"
      "Only the coordinator configures modules: an operator acts with its authority only with\n"
      "--as coordinator."};
  std::string module, command, as = "operator";
  oscar::SystemOptions tool;
  std::vector<std::string> args;
  int timeout_ms = 3000;
  app.add_option("module", module, "target module")->required();
  app.add_option("command", command, "command kind")->required();
  app.add_option("args", args, "command arguments");
  app.add_option("--as", as, "sender authority: coordinator, registry, boot (default: operator)");
  tool.add_to(app);
  auto* timeout = app.add_option("--timeout-ms", timeout_ms,
                                 "how long to wait for the module's reply (default 3000; a rewire "
                                 "adds its WAIT)");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    const auto kind = oscar::parse_command_kind(command);
    if (kind == oscar::CMD_REWIRE && timeout->count() == 0) {
      // The module replies after the new source matched (up to 2 s) and sent its first cue.
      const auto wait = args.size() == 4 ? oscar::parse_duration(args[3]) : std::chrono::seconds(1);
      timeout_ms +=
          static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(wait).count());
    }
    auto participant = tool.participant("oscar-config");
    oscar::ConfigClient client(*participant, as);
    const auto reply = client.send(module, kind, args, std::chrono::milliseconds(timeout_ms));
    if (!reply.ok()) {
      std::fprintf(stderr, "oscar config: %s: %s\n", module.c_str(), reply.error().c_str());
      return 1;
    }
    std::cout << fmt::format("{}: ok ({}{})\n", module, reply.state().last_transition(),
                             reply.state().suspended() ? ", suspended" : "");
    if (!reply.note().empty()) std::cout << fmt::format("  note: {}\n", reply.note());
    for (const auto& k : reply.state().kernels()) {
      std::cout << fmt::format(
          "  {} ({}): {}{}{}\n", k.name(), k.type(), k.mode(),
          k.cycle_ns() ? " " + oscar::format_duration(std::chrono::nanoseconds(k.cycle_ns())) : "",
          k.stub() ? " [stub]" : "");
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar config: %s\n", e.what());
    return 2;
  }
}
