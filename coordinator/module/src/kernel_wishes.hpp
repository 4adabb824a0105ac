#pragma once
// The coordinator's side of kernels' resource wishes (seed 004 §2.4, docs/coordinator.md
// "Resource wishes of kernels", not installed): each kernel of `coordinator: wishes:` is an
// applet "module/kernel" in the scheduler without code; its bundles are requested and released as
// the module's kernels ask and drop them (oscar/sched/wishes), a revocation is yielded at once,
// and a module that is not running (or a newer start of it) wishes nothing of its predecessor's.

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "oscar/applets/runtime.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/registry/system_spec.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "providers.hpp"

namespace oscar::coordinator {

class KernelWishes {
 public:
  /// Takes the notifications of the wishing kernels' applets (before the runtime starts).
  KernelWishes(const SystemSpec& system, applets::Runtime& runtime, DdsParticipant& participant,
               std::function<void()> wake);
  ~KernelWishes();
  KernelWishes(const KernelWishes&) = delete;
  KernelWishes& operator=(const KernelWishes&) = delete;

  /// The module whose kernel `applet` stands for, or "" if it is no kernel's.
  std::string module_of(const std::string& applet) const;
  /// Requests and releases the kernels' bundles as their modules ask now, and yields what the
  /// scheduler revokes. `modules`: what the registry says (a module it has not reported is taken
  /// at its word).
  void apply(const std::map<std::string, Providers::ModuleStatus>& modules);

 private:
  struct Asked {  // the latest set a module sent
    unsigned long incarnation = 0;
    unsigned long long seq = 0;
    std::map<std::string, std::set<std::string>> kernels;  // kernel -> bundles
  };
  void on_wishes(const SchedModuleWishes& w);

  applets::Runtime& runtime_;
  std::function<void()> wake_;
  std::map<std::string, std::string> module_of_;  // applet "module/kernel" -> module
  std::set<std::string> warned_;                  // unknown wishes, said once (apply() only)
  std::mutex mutex_;                              // what follows
  std::map<std::string, Asked> asked_;            // by module
  std::vector<applets::BundleId> to_yield_;       // revocations to answer
  std::unique_ptr<TopicReader<SchedModuleWishes, SchedModuleWishesPubSubType>> reader_;
};

}  // namespace oscar::coordinator
