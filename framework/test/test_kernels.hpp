#pragma once
// Small kernels for the framework's own tests (registered in test_kernels.cpp).

#include <atomic>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "oscar/command_types.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/kernel.hpp"

namespace oscar::test {

/// Publishes Bool cues (value alternates) on every cycle; stub publishes `false` only.
class Counter final : public Kernel {
 public:
  explicit Counter(KernelSetup& setup) : out_(setup.output<Bool>("out")) {}
  void process(Cycle&) override {
    Bool b;
    b.value(++count_ % 2 == 1);
    out_.publish(b);
  }
  void stub(Cycle&) override {
    ++stubs_;
    out_.publish(Bool{});
  }
  void on_activate() override { ++activations_; }
  void on_deactivate() override { ++deactivations_; }
  std::atomic<int> count_{0}, stubs_{0}, activations_{0}, deactivations_{0};

 private:
  Output<Bool>& out_;
};

/// Keeps every Bool cue it receives (as the shared pointers it was handed).
class Collect final : public Kernel {
 public:
  struct Params {
    int factor = 1;
    void describe(ParamSpec& spec) { spec.field("factor", factor, "a number").at_least(1); }
  };
  explicit Collect(KernelSetup& setup) : in_(setup.input<Bool>("in")) { setup.params(params_); }
  void process(Cycle&) override {
    std::lock_guard lock(mutex_);
    ++runs_;
    for (auto& r : in_.take_new()) seen_.push_back(r.cue);
  }
  void stub(Cycle& c) override { process(c); }
  std::vector<std::shared_ptr<const Bool>> seen() {
    std::lock_guard lock(mutex_);
    return seen_;
  }
  int runs() {
    std::lock_guard lock(mutex_);
    return runs_;
  }
  Input<Bool>& in_;
  Params params_;

 private:
  std::mutex mutex_;
  std::vector<std::shared_ptr<const Bool>> seen_;
  int runs_ = 0;
};

/// Keeps every cue of any type that reaches the inputs the configuration names (as the logger).
class RawCollect final : public Kernel {
 public:
  explicit RawCollect(KernelSetup& setup) {
    for (const auto& name : setup.configured_inputs()) {
      inputs_.push_back(&setup.raw_input(name, {.depth = 64}));
    }
  }
  void process(Cycle&) override {
    std::lock_guard lock(mutex_);
    for (auto* in : inputs_) {
      for (auto& r : in->take_new()) seen_.push_back(r.cue);
    }
  }
  void stub(Cycle& c) override { process(c); }
  std::vector<std::shared_ptr<const RawCue>> seen() {
    std::lock_guard lock(mutex_);
    return seen_;
  }

 private:
  std::vector<Input<RawCue>*> inputs_;
  std::mutex mutex_;
  std::vector<std::shared_ptr<const RawCue>> seen_;
};

/// Publishes Bool cues on an output of the QoS class its parameters declare, `count` of them
/// (0 = no end): a producer for the cue QoS tests.
class Emitter final : public Kernel {
 public:
  struct Params {
    bool reliable = true;
    bool transient_local = false;
    int depth = 16;
    int count = 0;
    void describe(ParamSpec& spec) {
      spec.field("reliable", reliable, "reliable output (else best effort)").fixed();
      spec.field("transient_local", transient_local, "late joiners get the history").fixed();
      spec.field("depth", depth, "output ring and history").at_least(1).fixed();
      spec.field("count", count, "cues to publish; 0 = unlimited").at_least(0);
    }
  };
  explicit Emitter(KernelSetup& setup) {
    setup.params(params_);
    out_ = &setup.output<Bool>("out", {.depth = static_cast<std::size_t>(params_.depth),
                                       .reliable = params_.reliable,
                                       .transient_local = params_.transient_local});
  }
  void process(Cycle&) override {
    if (params_.count > 0 && sent_ >= params_.count) return;
    ++sent_;
    out_->publish(Bool{});
  }
  void stub(Cycle& c) override { process(c); }

 private:
  Params params_;
  Output<Bool>* out_ = nullptr;
  int sent_ = 0;
};

/// Like Collect, but declares that its input needs reliable delivery.
class ReliableCollect final : public Kernel {
 public:
  explicit ReliableCollect(KernelSetup& setup)
      : in_(setup.input<Bool>("in", {.reliability = Reliability::kReliable})) {}
  void process(Cycle&) override { in_.take_new(); }
  void stub(Cycle& c) override { process(c); }
  Input<Bool>& in_;
};

/// Declares its input's options as a kernel that needs a deep ring of prefetched cues would.
class Prefetching final : public Kernel {
 public:
  explicit Prefetching(KernelSetup& setup)
      : in_(setup.input<Bool>("in", {.depth = 64, .transfer = Transfer::kPrefetch})) {}
  void process(Cycle&) override {}
  void stub(Cycle&) override {}
  Input<Bool>& in_;
};

/// Publishes LineSeg3DSeq cues: for type-mismatch tests.
class Lines final : public Kernel {
 public:
  explicit Lines(KernelSetup& setup) : out_(setup.output<LineSeg3DSeq>("out")) {}
  void process(Cycle&) override { out_.publish(LineSeg3DSeq{}); }
  void stub(Cycle& c) override { process(c); }

 private:
  Output<LineSeg3DSeq>& out_;
};

/// Merges two Bool inputs: for the multi-core branching/merging rule.
class Merge final : public Kernel {
 public:
  explicit Merge(KernelSetup& setup)
      : a_(setup.input<Bool>("a")), b_(setup.input<Bool>("b")), out_(setup.output<Bool>("out")) {}
  void process(Cycle&) override {
    if (a_.latest() && b_.latest()) out_.publish(Bool{});
  }
  void stub(Cycle&) override { out_.publish(Bool{}); }

 private:
  Input<Bool>& a_;
  Input<Bool>& b_;
  Output<Bool>& out_;
};

}  // namespace oscar::test

namespace oscar::test {
/// Holds a GvImage input (for prefetch tests); does nothing by itself.
class CollectImage final : public Kernel {
 public:
  explicit CollectImage(KernelSetup& setup) : in_(setup.input<GvImage>("in")) {}
  void process(Cycle&) override {}
  void stub(Cycle&) override {}
  Input<GvImage>& in_;
};
/// Fails as told: in on_activate() or in process() (every call, or all but every `succeed_every`
/// -th), with "sensor unplugged"; for the kernel-error policy's tests.
class Failing final : public Kernel {
 public:
  struct Params {
    std::string fail_in = "process";  // process | on_activate
    int succeed_every = 0;            // 0: never
    void describe(ParamSpec& spec) {
      spec.field("fail_in", fail_in, "process or on_activate");
      spec.field("succeed_every", succeed_every, "every n-th process() returns (0: none)")
          .at_least(0);
    }
  };
  explicit Failing(KernelSetup& setup) { setup.params(params_); }
  void process(Cycle&) override {
    const int call = ++calls_;
    if (params_.succeed_every > 0 && call % params_.succeed_every == 0) return;
    throw std::runtime_error("sensor unplugged");
  }
  void stub(Cycle& c) override { process(c); }
  void on_activate() override {
    ++activations_;
    if (params_.fail_in == "on_activate") throw std::runtime_error("sensor unplugged");
  }
  std::atomic<int> calls_{0}, activations_{0};

 private:
  Params params_;
};

/// Asks for its wish `look` on every cycle and never drops it (the frame withdraws it while the
/// kernel is deactivated).
class Wisher final : public Kernel {
 public:
  explicit Wisher(KernelSetup& setup) : look_(setup.wish("look")) {}
  void process(Cycle&) override { look_.ask(); }
  void stub(Cycle&) override { look_.ask(); }
  Wish& look_;
};

}  // namespace oscar::test

namespace oscar::test {
/// Takes commands (docs/kernels.md, "Command ports"): `hold` (a Bool; refused when false) and
/// `mode` (a SetFrameMode; "boom" throws). Each answer says whether the command ran on the
/// thread that runs process() and whether it came while process() ran. Publishes a Bool a cycle.
class Commanded final : public Kernel {
 public:
  explicit Commanded(KernelSetup& setup) : out_(setup.output<Bool>("out")) {
    setup.command<Bool>("hold", [this](const Bool& b) { return hold(b); });
    setup.command<SetFrameMode>("mode", [this](const SetFrameMode& m) {
      if (m.mode() == "boom") throw std::runtime_error("boom");
      mode_ = m.mode();
      return CommandAnswer::accept("mode " + m.mode());
    });
  }
  void process(Cycle&) override {
    in_process_ = true;
    process_thread_ = std::this_thread::get_id();
    Bool b;
    b.value(++cycles_ % 2 == 1);
    out_.publish(b);
    in_process_ = false;
  }
  void stub(Cycle& c) override { process(c); }
  void on_activate() override { ++activations_; }
  CommandAnswer hold(const Bool& b) {
    ++commands_;
    const bool during_process = in_process_;
    const bool same_thread = process_thread_.load() == std::this_thread::get_id();
    if (!b.value()) return CommandAnswer::refuse("told not to hold");
    return CommandAnswer::accept(std::string("held; on the processing thread: ") +
                                 (same_thread ? "yes" : "no") +
                                 "; during process(): " + (during_process ? "yes" : "no"));
  }
  std::atomic<int> cycles_{0}, commands_{0}, activations_{0};
  std::string mode_;  // written and read on the processing thread only

 private:
  Output<Bool>& out_;
  std::atomic<bool> in_process_{false};
  std::atomic<std::thread::id> process_thread_{};
};
}  // namespace oscar::test
