// oscar applets ps [--json]: the plan of the running system's coordinator (docs/coordinator.md).
#include "ps.hpp"

#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <optional>

#include "oscar/coordinator/plan_json.hpp"
#include "oscar/registry/system_options.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::tools {

void add_ps(CLI::App& app, PsOptions& options) {
  auto* ps = app.add_subcommand("ps", "The running system's services, their holders and applets");
  options.tool.add_to(*ps);
  ps->add_flag("--json", options.json,
               R"(Print JSON: {"services":{"<service>":{"holders","access","waiting"}},)"
               R"("applets":[{"name","process","state"}]})");
  ps->add_option("--timeout", options.timeout_s, "seconds to wait for the coordinator's plan");
  options.command = ps;
}

int run_ps(const PsOptions& options) {
  auto participant = options.tool.participant("oscar-applets-ps");
  std::mutex mutex;
  std::condition_variable arrived;
  std::optional<AppletPlan> plan;
  TopicReader<AppletPlan, AppletPlanPubSubType> reader(*participant, topics::applet_plan(),
                                                       [&](const AppletPlan& p, const auto&) {
                                                         std::lock_guard lock(mutex);
                                                         plan = p;
                                                         arrived.notify_all();
                                                       });
  std::unique_lock lock(mutex);
  const auto timeout = std::chrono::milliseconds(static_cast<long>(options.timeout_s * 1000));
  if (!arrived.wait_for(lock, timeout, [&] { return plan.has_value(); })) {
    std::fprintf(stderr,
                 "oscar applets ps: no coordinator published its plan on domain %d within %.1f s "
                 "(does the system file have a coordinator: section?)\n",
                 participant->domain(), options.timeout_s);
    return 1;
  }
  const auto text =
      options.json ? coordinator::plan_json(*plan) + "\n" : coordinator::plan_table(*plan);
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace oscar::tools
