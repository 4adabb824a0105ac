#pragma once
// The peers of `oscar bench cueflow --all` (docs/benchmarks.md) and the RouDi the iceoryx peer
// needs. Included by cueflow_bench_main.cpp only.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "process.hpp"  // tests/common

namespace oscar::bench {

// A peer of --all: its system name in the JSON, the program that measures it (peers/), and
// whether it also crosses hosts (the remote constellation; the others are same-host mechanisms).
struct Peer {
  const char* system;
  const char* program;
  bool remote = false;
};
inline constexpr Peer kPeers[] = {
    {"fastdds_datasharing", "oscar-bench-fastdds-plain"},
    {"cyclonedds", "oscar-bench-cyclonedds", true},
    {"iceoryx", "oscar-bench-iceoryx"},
    {"floor", "oscar-bench-floor"},
};

// RouDi for the iceoryx rows, with mempools for the three rows' cues (16 in a subscriber's queue
// plus those in flight); Process stops it with SIGTERM, on which it removes its shared memory.
// None if it does not stay up (e.g. another RouDi runs on this machine).
inline std::unique_ptr<oscar::test::Process> start_roudi(const std::filesystem::path& dir) {
  const auto config = dir / "roudi.toml";
  std::ofstream(config) << "[general]\nversion = 1\n\n[[segment]]\n\n"
                           "[[segment.mempool]]\nsize = 128\ncount = 64\n\n"
                           "[[segment.mempool]]\nsize = 8192\ncount = 64\n\n"
                           "[[segment.mempool]]\nsize = 524288\ncount = 64\n";
  auto roudi = std::make_unique<oscar::test::Process>(
      std::vector<std::string>{"/usr/bin/iox-roudi", "-c", config.string(), "-l", "warning"},
      (dir / "roudi.log").string());
  std::this_thread::sleep_for(std::chrono::seconds(1));
  if (roudi->wait(std::chrono::milliseconds(0))) {
    std::cerr << "bench cueflow: iox-roudi did not stay up, no iceoryx rows: " << roudi->output();
    return nullptr;
  }
  return roudi;
}

}  // namespace oscar::bench
