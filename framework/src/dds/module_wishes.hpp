#pragma once
// A module's resource wishes on the wire (docs/kernels.md, "Resource wishes"): the asked wishes
// of its active kernels go to the coordinator on oscar/sched/wishes, the whole set at each
// change; whether each is granted comes back in the coordinator's plan (the applet entry
// "module/kernel" lists its granted bundles).

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "oscar/dds_participant.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "oscar/wish.hpp"

namespace oscar::internal {

class ModuleWishes {
 public:
  struct Entry {
    Wish* wish;
    const std::atomic<bool>* kernel_active;  // a deactivated kernel wishes nothing
  };
  ModuleWishes(DdsParticipant& participant, std::string module, unsigned long incarnation,
               std::vector<Entry> entries);
  /// Detaches from the wishes: no kernel reaches this object any more.
  ~ModuleWishes();
  ModuleWishes(const ModuleWishes&) = delete;
  ModuleWishes& operator=(const ModuleWishes&) = delete;

  /// Sends the asked wishes of the active kernels, if they changed since the last time.
  void publish();

 private:
  void on_plan(const AppletPlan& plan);

  std::string module_;
  unsigned long incarnation_;
  std::vector<Entry> entries_;
  std::mutex mutex_;  // publish() runs on the processing and configuration threads
  std::vector<SchedKernelWish> sent_;
  bool sent_any_ = false;
  unsigned long long seq_ = 0;
  TopicWriter<SchedModuleWishes, SchedModuleWishesPubSubType> writer_;
  std::unique_ptr<TopicReader<AppletPlan, AppletPlanPubSubType>> plan_reader_;
};

}  // namespace oscar::internal
