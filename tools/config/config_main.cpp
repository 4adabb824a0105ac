// oscar config MODULE COMMAND [ARGS...]: sends one configuration command and prints the reply.
#include <cstdio>
#include <iostream>

#include <yaml-cpp/yaml.h>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include <oscar/config_client.hpp>
#include <oscar/registry/registry_client.hpp>
#include <oscar/registry/system_options.hpp>
#include <oscar/time.hpp>

#include "idl_types.hpp"  // tools/inspect
#include "oscar/type_texts.hpp"

namespace {

// `command KERNEL NAME [YAML]`: the request is encoded from YAML as the IDL type the kernel
// declares for NAME, which the module's published state names: one of OSCAR's types
// (idl/oscar/*.idl), or a type of the module's own whose IDL text the module announced
// (oscar/type_texts.hpp).
int send_command(oscar::ConfigClient& client, const oscar::AnnouncedTypes& announced,
                 const std::string& module, const std::vector<std::string>& args,
                 std::chrono::milliseconds timeout) {
  if (args.size() < 2 || args.size() > 3) {
    throw std::invalid_argument(fmt::format(
        "command takes KERNEL NAME [YAML] (the request as a YAML map, e.g. '{{mode: half}}'), "
        "got {} argument(s)",
        args.size()));
  }
  const auto& kernel = args[0];
  const auto& name = args[1];
  const auto state = client.module_state(module, timeout);
  const oscar::KernelState* k = nullptr;
  std::vector<std::string> kernels;
  for (const auto& ks : state.kernels()) {
    if (ks.name() == kernel) k = &ks;
    kernels.push_back(ks.name());
  }
  if (!k) {
    throw std::invalid_argument(fmt::format("module '{}' has no kernel '{}' (kernels: {})", module,
                                            kernel, fmt::join(kernels, ", ")));
  }
  std::string type, known;
  for (const auto& c : k->commands()) {
    if (c.name() == name) type = c.type();
    known += fmt::format("{}{} ({})", known.empty() ? "" : ", ", c.name(), c.type());
  }
  if (type.empty()) {
    throw std::invalid_argument(
        known.empty() ? fmt::format("kernel '{}' ({}) has no command '{}': it declares no commands",
                                    kernel, k->type(), name)
                      : fmt::format("kernel '{}' ({}) has no command '{}'; its commands: {}",
                                    kernel, k->type(), name, known));
  }
  const auto text = announced.wait_for(type, timeout);
  if (!text) {
    throw std::invalid_argument(fmt::format(
        "command '{}' of kernel '{}' takes {}, whose IDL oscar config does not know: OSCAR does "
        "not define it and module '{}' announced no IDL text for it",
        name, kernel, type, module));
  }
  oscar::inspect::IdlTypes types;
  types.add(*text);
  YAML::Node request;
  try {
    request = YAML::Load(args.size() == 3 ? args[2] : "{}");
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(fmt::format("the request is no YAML: {}", e.what()));
  }
  std::vector<std::uint8_t> cdr;
  try {
    cdr = types.from_yaml(type, request);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("the request is no {}: {}", type, e.what()));
  }
  const auto reply = client.send_command(module, kernel, name, type, std::move(cdr), timeout);
  if (!reply.ok()) {
    std::fprintf(stderr, "oscar config: %s: %s\n", module.c_str(), reply.error().c_str());
    return 1;
  }
  std::cout << fmt::format("{}: {} accepted {}{}\n", module, kernel, name,
                           reply.answer().empty() ? "" : ": " + reply.answer());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "oscar config: send a configuration command to a module (docs/kernels.md).\n"
      "Commands: activate KERNEL|* [MODE], deactivate KERNEL|*, trigger KERNEL|*,\n"
      "set-cycle KERNEL CYCLE, set-param KERNEL NAME VALUE, rewire KERNEL INPUT SOURCE [WAIT]\n"
      "(WAIT: longest wait for the new source's first cue, default 1s),\n"
      "suspend, resume, stub KERNEL|* on|off, shutdown,\n"
      "command KERNEL NAME [YAML] (a kernel's command port; the request as YAML, e.g.\n"
      "'{mode: half}', encoded as the IDL type the kernel declares).\n"
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
    auto participant = tool.participant("oscar-config", oscar::ToolAuthority::kActAsBoot);
    oscar::ConfigClient client(*participant, as);
    if (kind == oscar::CMD_COMMAND) {
      const oscar::AnnouncedTypes announced(*participant);
      return send_command(client, announced, module, args, std::chrono::milliseconds(timeout_ms));
    }
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
