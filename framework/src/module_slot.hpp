#pragma once
// The frame's bookkeeping for one kernel (internal to Module).

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <string>

#include "oscar/kernel_instance.hpp"
#include "oscar/module.hpp"
#include "oscar/module_spec.hpp"

namespace oscar {

struct Module::Slot {
  const KernelSpec* spec = nullptr;
  std::unique_ptr<KernelInstance> instance;
  ModeSpec mode;
  bool stub = false;
  std::atomic<bool> active{false};  // on_activate() ran and on_deactivate() did not
  bool pending = false;             // a trigger arrived and the kernel has not run since
  std::chrono::steady_clock::time_point next_due{};
  std::uint64_t overruns = 0;
  std::string failure;                         // the last exception from process()/stub(), if any
  std::map<std::string, std::string> sources;  // input -> "<kernel>/<channel>", after rewires

  bool continuous() const { return mode.kind == ModeSpec::Kind::kContinuous; }
  bool single_step() const { return mode.kind == ModeSpec::Kind::kSingleStep; }
};

}  // namespace oscar
