#include "module_wishes.hpp"

#include <algorithm>
#include <map>

namespace oscar::internal {

ModuleWishes::ModuleWishes(DdsParticipant& participant, std::string module,
                           unsigned long incarnation, std::vector<Entry> entries)
    : module_(std::move(module)),
      incarnation_(incarnation),
      entries_(std::move(entries)),
      writer_(participant, topics::sched_wishes()) {
  for (auto& e : entries_) e.wish->on_change([this] { publish(); });
  plan_reader_ = std::make_unique<TopicReader<AppletPlan, AppletPlanPubSubType>>(
      participant, topics::applet_plan(), [this](const AppletPlan& p, const auto&) { on_plan(p); });
  publish();  // the first set (empty): a coordinator forgets what an earlier start asked
}

ModuleWishes::~ModuleWishes() {
  for (auto& e : entries_) e.wish->on_change({});  // waits for a call under way
  plan_reader_.reset();
}

void ModuleWishes::publish() {
  std::vector<SchedKernelWish> now;
  for (const auto& e : entries_) {
    if (!e.wish->asked() || !e.kernel_active->load()) continue;
    auto it = std::find_if(now.begin(), now.end(),
                           [&](const auto& k) { return k.kernel() == e.wish->kernel(); });
    if (it == now.end()) {
      now.emplace_back().kernel(e.wish->kernel());
      it = std::prev(now.end());
    }
    it->asked().push_back(e.wish->name());
  }
  std::lock_guard lock(mutex_);
  if (sent_any_ && now == sent_) return;
  SchedModuleWishes sample;
  sample.module_name(module_);
  sample.incarnation(incarnation_);
  sample.seq(++seq_);
  sample.kernels(now);
  writer_.write(sample);
  sent_ = std::move(now);
  sent_any_ = true;
}

void ModuleWishes::on_plan(const AppletPlan& plan) {
  std::map<std::string, const std::vector<std::string>*> granted;  // kernel -> bundles
  const auto prefix = module_ + "/";
  for (const auto& a : plan.applets()) {
    if (a.name().starts_with(prefix)) granted[a.name().substr(prefix.size())] = &a.granted();
  }
  for (auto& e : entries_) {
    const auto it = granted.find(e.wish->kernel());
    e.wish->set_granted(it != granted.end() && std::find(it->second->begin(), it->second->end(),
                                                         e.wish->name()) != it->second->end());
  }
}

}  // namespace oscar::internal
