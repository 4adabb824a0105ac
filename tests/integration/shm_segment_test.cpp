// Each participant's shared-memory segment (docs/network.md, "Shared memory"): what a module
// sends waits there until every reader on the host took it. A module that publishes cues gets
// room for images, one without outputs a small segment, and the system file's
// `network.shm_segment_bytes` is taken as it is. Each module runs alone in an oscar-run child, so
// the only segment it maps is its own.
#include <chrono>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "oscar/network.hpp"
#include "oscar/testing/eventually.hpp"
#include "process.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;

// The bytes of the largest Fast DDS segment `pid` maps (its ports' small files left out); 0 if
// none yet.
std::uint64_t segment_bytes(pid_t pid) {
  std::ifstream maps("/proc/" + std::to_string(pid) + "/maps");
  std::uint64_t largest = 0;
  for (std::string line; std::getline(maps, line);) {
    if (line.find("/dev/shm/fastrtps_") == std::string::npos ||
        line.find("/dev/shm/fastrtps_port") != std::string::npos)
      continue;
    std::uint64_t from = 0, to = 0;
    char dash = 0;
    std::istringstream(line) >> std::hex >> from >> dash >> to;
    largest = std::max(largest, to - from);
  }
  return largest;
}

// What `pid` maps of /dev/shm, for a failure's message.
std::string shm_maps(pid_t pid) {
  std::ifstream maps("/proc/" + std::to_string(pid) + "/maps");
  std::string out;
  for (std::string line; std::getline(maps, line);) {
    if (line.find("/dev/shm/") != std::string::npos) out += line + "\n";
  }
  return out;
}

// The module's segment (Fast DDS adds its bookkeeping to the size it is given), once it maps one:
// 64 KiB at least, the least a segment may be (seen: a 4 KiB mapping of a fastrtps_ file for a
// moment while the participant starts).
void expect_segment(test::Process& module, std::uint32_t asked) {
  std::uint64_t mapped = 0;
  eventually([&] { return (mapped = segment_bytes(module.pid())) >= (64u << 10); }, 20s);
  const auto what = shm_maps(module.pid()) + module.output();
  EXPECT_GE(mapped, asked) << what;
  EXPECT_LT(mapped, asked + (256u << 10)) << what;
}

TEST(ShmSegment, AModuleThatPublishesCuesGetsRoomForImagesOneWithoutOutputsLittle) {
  {
    auto source = test::run_module("shm_source", {"-k", "bench_source:src", "-m", "continuous:1s"});
    expect_segment(*source, kCueShmSegmentBytes);
  }
  auto sink = test::run_module(
      "shm_sink", {"-k", "bench_sink:sink", "-i", "sink.in=absent/out", "-m", "single_step"});
  expect_segment(*sink, kQuietShmSegmentBytes);
}

TEST(ShmSegment, TheSystemFilesSizeIsTakenAsItIs) {
  const auto file = test::temp_path("shm_segment.yaml");
  std::ofstream(file) << R"(
name: shm_sink
network: { shm_segment_bytes: 3145728 }
kernels: [ { type: bench_sink, name: sink, inputs: { in: absent/out } } ]
)";
  test::Process sink(
      {test::bin("oscar-run"), file, "--domain", std::to_string(test::test_domain())},
      test::temp_path("shm_sink.log"));
  expect_segment(sink, 3u << 20);
  std::remove(file.c_str());
}

}  // namespace
}  // namespace oscar
