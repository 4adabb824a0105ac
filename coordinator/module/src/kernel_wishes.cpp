#include "kernel_wishes.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

namespace oscar::coordinator {

KernelWishes::KernelWishes(const SystemSpec& system, applets::Runtime& runtime,
                           DdsParticipant& participant, std::function<void()> wake)
    : runtime_(runtime), wake_(std::move(wake)) {
  if (!system.coordinator) return;
  for (const auto& w : system.coordinator->wishes) {
    module_of_[w.applet()] = w.module;
    // A kernel does not negotiate: what the plan gives to others it hands over at once.
    runtime_.set_remote(w.applet(), [this](const applets::Notification& n) {
      if (n.kind != applets::Notification::Kind::kRevokeRequested) return;
      {
        std::lock_guard lock(mutex_);
        to_yield_.push_back(n.bundle);
      }
      wake_();
    });
  }
  reader_ = std::make_unique<TopicReader<SchedModuleWishes, SchedModuleWishesPubSubType>>(
      participant, topics::sched_wishes(),
      [this](const SchedModuleWishes& w, const auto&) { on_wishes(w); });
}

KernelWishes::~KernelWishes() { reader_.reset(); }

std::string KernelWishes::module_of(const std::string& applet) const {
  const auto it = module_of_.find(applet);
  return it == module_of_.end() ? "" : it->second;
}

void KernelWishes::on_wishes(const SchedModuleWishes& w) {
  {
    std::lock_guard lock(mutex_);
    auto& a = asked_[w.module_name()];
    // Samples of one start come in order; a newer start replaces an older one's.
    if (w.incarnation() < a.incarnation ||
        (w.incarnation() == a.incarnation && w.seq() <= a.seq && a.seq != 0)) {
      return;
    }
    a.incarnation = w.incarnation();
    a.seq = w.seq();
    a.kernels.clear();
    for (const auto& k : w.kernels()) {
      a.kernels[k.kernel()].insert(k.asked().begin(), k.asked().end());
    }
  }
  wake_();
}

void KernelWishes::apply(const std::map<std::string, Providers::ModuleStatus>& modules) {
  std::map<std::string, Asked> asked;
  std::vector<applets::BundleId> to_yield;
  {
    std::lock_guard lock(mutex_);
    asked = asked_;
    to_yield.swap(to_yield_);
  }
  runtime_.with_scheduler([&](applets::Scheduler& s) {
    const auto& m = s.model();
    for (const auto& [applet, module] : module_of_) {
      const auto kernel = applet.substr(module.size() + 1);
      std::set<std::string> wanted;
      const auto status = modules.find(module);
      const auto a = asked.find(module);
      const bool current =
          a != asked.end() &&
          (status == modules.end() ||
           (status->second.running && a->second.incarnation == status->second.incarnation));
      if (current) {
        if (const auto k = a->second.kernels.find(kernel); k != a->second.kernels.end()) {
          wanted = k->second;
        }
      }
      const auto id = m.applet_id(applet);
      std::set<std::string> known;
      for (const auto b : m.applet(id).bundles) {
        const auto& name = m.bundle(b).name;
        known.insert(name);
        const bool want = wanted.contains(name);
        if (want == s.requested(b)) continue;
        try {
          if (want) {
            s.request(b);
          } else {
            s.release(b);
          }
          spdlog::info("coordinator: kernel {} {} its wish {}", applet,
                       want ? "asks for" : "withdraws", name);
        } catch (const std::invalid_argument& e) {
          if (warned_.insert(applet + "/" + name).second) {
            spdlog::warn("coordinator: kernel {}'s wish {}: {}", applet, name, e.what());
          }
        }
      }
      for (const auto& w : wanted) {
        if (!known.contains(w) && warned_.insert(applet + "/" + w).second) {
          spdlog::warn(
              "coordinator: kernel {} wishes '{}', which coordinator: wishes: does not declare "
              "for it (its wishes: {})",
              applet, w, fmt::join(known, ", "));
        }
      }
    }
    for (const auto b : to_yield) s.yield(b);
  });
  for (const auto& [module, a] : asked) {
    for (const auto& [kernel, bundles] : a.kernels) {
      const auto applet = module + "/" + kernel;
      if (!module_of_.contains(applet) && !bundles.empty() && warned_.insert(applet).second) {
        spdlog::warn(
            "coordinator: kernel {} wishes {}, but coordinator: wishes: does not list "
            "the kernel",
            applet, fmt::join(bundles, ", "));
      }
    }
  }
}

}  // namespace oscar::coordinator
