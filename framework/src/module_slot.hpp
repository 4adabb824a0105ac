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
  std::uint64_t failures = 0;  // calls of on_activate()/process()/stub() that threw
  int failures_in_a_row = 0;   // since the last call that returned (KernelErrorPolicy)
  std::string failure;         // the last one: "process(): <what>"
  std::map<std::string, std::string> sources;  // input -> "<kernel>/<channel>", after rewires

  bool continuous() const { return mode.kind == ModeSpec::Kind::kContinuous; }
  bool single_step() const { return mode.kind == ModeSpec::Kind::kSingleStep; }
};

}  // namespace oscar
