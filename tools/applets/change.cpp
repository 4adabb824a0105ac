// oscar applets add FILE.yaml / oscar applets remove --applet NAME | --service NAME: the
// coordinator's command port `applet` with the events `add` and `remove` (docs/coordinator.md).
#include "change.hpp"

#include <chrono>
#include <cstdio>

#include "oscar/applets/config.hpp"
#include "oscar/config_client.hpp"
#include "oscar/coordinator/plan_json.hpp"  // AppletEvent as an IDL type
#include "oscar/registry/system_spec.hpp"

namespace oscar::tools {

void add_change(CLI::App& app, ChangeOptions& options) {
  auto* add = app.add_subcommand(
      "add", "Add services and applets to the running system (YAML: services: and/or applets:)");
  options.tool.add_to(*add);
  add->add_option("file", options.file,
                  "YAML with services: (as in the system file) and/or applets: (as entries of "
                  "coordinator: applets:)")
      ->required();
  add->add_option("--timeout", options.timeout_s, "seconds to wait for the coordinator's answer");
  options.add = add;
  auto* remove =
      app.add_subcommand("remove", "Remove an applet or a service from the running system");
  options.tool.add_to(*remove);
  auto* applet = remove->add_option("--applet", options.applet, "the applet to remove");
  auto* service = remove->add_option("--service", options.service, "the service to remove");
  applet->excludes(service);
  remove->add_option("--timeout", options.timeout_s,
                     "seconds to wait for the coordinator's answer");
  options.remove = remove;
}

int run_change(const ChangeOptions& options) {
  AppletEvent e;
  std::string what;
  if (options.add->parsed()) {
    e.event("add");
    e.spec(applets::read_text_file(options.file));
    e.spec_name(options.file);
    what = options.file;
  } else {
    if (options.applet.empty() && options.service.empty()) {
      std::fprintf(stderr, "oscar applets remove: name --applet NAME or --service NAME\n");
      return 2;
    }
    e.event("remove");
    e.applet(options.applet);
    e.service(options.service);
    what = options.applet.empty() ? "service " + options.service : "applet " + options.applet;
  }
  auto participant = options.tool.participant("oscar-applets-change", ToolAuthority::kActAsBoot);
  // The coordinator's command port takes an operator's events from a tool as from boot.
  ConfigClient client(*participant, "boot");
  const auto timeout = std::chrono::milliseconds(static_cast<long>(options.timeout_s * 1000));
  ConfigReply reply;
  try {
    reply = client.command(SystemSpec::kCoordinatorModule, SystemSpec::kCoordinatorModule, "applet",
                           e, timeout);
  } catch (const std::exception& x) {
    std::fprintf(stderr, "oscar applets %s: no answer from the coordinator on domain %d: %s\n",
                 e.event().c_str(), participant->domain(), x.what());
    return 2;
  }
  if (!reply.ok()) {
    // The coordinator's own reason, when it answered (not the frame's wrapping of it).
    const auto& why = reply.answered() && !reply.answer().empty() ? reply.answer() : reply.error();
    std::fprintf(stderr, "oscar applets %s: refused: %s\n", e.event().c_str(), why.c_str());
    return 1;
  }
  std::printf("%s: %s\n", what.c_str(), reply.answer().empty() ? "done" : reply.answer().c_str());
  return 0;
}

}  // namespace oscar::tools
