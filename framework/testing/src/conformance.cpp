#include "oscar/testing/conformance.hpp"

#include <filesystem>
#include <set>

#include "oscar/cue_types.hpp"
#include "oscar/harness.hpp"

namespace oscar::conformance {
namespace {
std::size_t entries(const char* dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}
}  // namespace

void expect_kernel_conformance(const std::string& type, const YAML::Node& params) {
  register_standard_cue_types();
  SCOPED_TRACE("kernel type " + type);

  // Construction only declares: no threads, no open files.
  const auto threads = entries("/proc/self/task");
  const auto fds = entries("/proc/self/fd");
  {
    KernelHarness a(type, YAML::Clone(params), "a");
    KernelHarness b(type, YAML::Clone(params), "b");
    EXPECT_EQ(entries("/proc/self/task"), threads) << "the constructor started a thread";
    EXPECT_EQ(entries("/proc/self/fd"), fds) << "the constructor opened a file or device";
  }

  KernelHarness h(type, YAML::Clone(params));
  auto& ports = h.instance().ports();
  std::set<std::string> names;
  for (const auto& p : ports.inputs) EXPECT_TRUE(names.insert(p->name()).second) << p->name();
  for (const auto& p : ports.outputs) EXPECT_TRUE(names.insert(p->name()).second) << p->name();

  // process() with nothing on any input must neither throw nor crash.
  const auto configured = ports.params.to_yaml();
  EXPECT_NO_THROW(h.step()) << "process() must survive empty inputs";

  // stub() writes every output.
  for (const auto& p : ports.outputs) (void)h.take_count(p->name());  // drop earlier cues
  EXPECT_NO_THROW(h.step_stub());
  for (const auto& p : ports.outputs) {
    EXPECT_GE(h.take_count(p->name()), 1u)
        << "stub() wrote nothing to output '" << p->name() << "'";
  }

  // The parameters are the frame's: it reads them from other threads (oscar ps) while the kernel
  // runs, so a kernel keeps what it derives from them in members of its own.
  const auto yaml = ports.params.to_yaml();
  EXPECT_EQ(yaml, configured) << "process() or stub() wrote to a parameter";

  // Parameters round-trip through YAML.
  KernelHarness again(type, YAML::Load(yaml), "again");
  EXPECT_EQ(again.instance().ports().params.to_yaml(), yaml);
}

}  // namespace oscar::conformance
