// What a restarted module gets back (oscar-run --restore), and the registry's cache of it.
#include "restore_text.hpp"

#include <gtest/gtest.h>

namespace oscar::internal {
namespace {

KernelState kernel(const std::string& name) {
  KernelState k;
  k.name(name);
  k.type("bench_source");
  k.mode("continuous");
  k.cycle_ns(100'000'000);
  k.params("{rate: 2}");
  k.inputs({"in=cam/out"});
  return k;
}

ModuleState module_with(std::vector<KernelState> kernels) {
  ModuleState s;
  s.module_name("m");
  s.kernels(std::move(kernels));
  return s;
}

TEST(RestoreText, ShowsModeStubParametersAndWiringOfEachKernel) {
  auto b = kernel("b");
  b.mode("single_step");
  b.trigger("input:in");
  b.stub(true);
  EXPECT_EQ(restore_text(module_with({kernel("a"), b})),
            "{a: {mode: continuous:100000000ns, stub: false, params: {rate: 2}, inputs: {in: "
            "cam/out}}, b: {mode: single_step:input:in, stub: true, params: {rate: 2}, inputs: "
            "{in: cam/out}}}");
}

TEST(RestoreTextCache, GivesWhatRestoreTextMakes) {
  RestoreTextCache cache;
  const auto state = module_with({kernel("a"), kernel("b")});
  EXPECT_EQ(cache.of(state), restore_text(state));
}

TEST(RestoreTextCache, IgnoresTheCountersEachAnnouncementChanges) {
  RestoreTextCache cache;
  auto state = module_with({kernel("a")});
  const auto before = cache.of(state);
  state.kernels()[0].cycles(41);
  state.kernels()[0].published(40);
  state.pid(77);
  EXPECT_EQ(cache.of(state), before);
}

TEST(RestoreTextCache, FollowsEveryChangeOfWhatTheTextSays) {
  RestoreTextCache cache;
  auto state = module_with({kernel("a")});
  cache.of(state);
  const auto follows = [&](const char* what) {
    EXPECT_EQ(cache.of(state), restore_text(state)) << "after a change of " << what;
  };
  state.kernels()[0].params("{rate: 5}");
  follows("parameters");
  state.kernels()[0].inputs({"in=cam2/out"});
  follows("wiring");
  state.kernels()[0].cycle_ns(50'000'000);
  follows("cycle");
  state.kernels()[0].mode("single_step");
  follows("mode");
  state.kernels()[0].trigger("command");
  follows("trigger");
  state.kernels()[0].stub(true);
  follows("stub");
  state.kernels()[0].name("a2");
  follows("kernel name");
  state.kernels().push_back(kernel("b"));
  follows("kernels");
}

}  // namespace
}  // namespace oscar::internal
