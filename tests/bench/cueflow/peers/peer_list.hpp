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
#if OSCAR_ZERO_COPY
#include "zero_copy/mempools.hpp"
#endif

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

#if OSCAR_ZERO_COPY
// RouDi for the iceoryx rows, with mempools for the three rows' cues (16 in a subscriber's queue
// plus those in flight), and for the zero-copy rows' plain cues (a ring of 16 at the source, a
// ring and a queue of 16 at the sink, loans); Process stops it with SIGTERM, on which it removes
// its shared memory. None if it does not stay up (e.g. another RouDi runs on this machine).
inline std::unique_ptr<oscar::test::Process> start_roudi(const std::filesystem::path& dir) {
  const auto config = dir / "roudi.toml";
  std::vector<oscar::zero_copy::Mempool> pools{{128, 64}, {8192, 64}, {524288, 64}};
  for (const auto& pool : oscar::zero_copy::plain_cue_mempools(64)) pools.push_back(pool);
  std::ofstream(config) << oscar::zero_copy::roudi_config(pools);
  auto roudi = std::make_unique<oscar::test::Process>(
      std::vector<std::string>{"/usr/bin/iox-roudi", "-c", config.string(), "-l", "warning"},
      (dir / "roudi.log").string());
  std::this_thread::sleep_for(std::chrono::seconds(1));
  if (roudi->wait(std::chrono::milliseconds(0))) {
    std::cerr << "bench cueflow: iox-roudi did not stay up, no iceoryx or zero-copy rows: "
              << roudi->output();
    return nullptr;
  }
  return roudi;
}
#endif

}  // namespace oscar::bench
