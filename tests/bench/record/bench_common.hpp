#pragma once
// What oscar bench record and oscar bench replay share: the five streams of issue 4 (four 30 Hz
// 768x576 GvImage streams and one 1 kHz Bool stream) and small helpers.

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "oscar/cue_types.hpp"
#include "process_cpu.hpp"  // tests/common

namespace oscar::bench {

struct Stream {
  std::string kernel;  ///< the topic is oscar/cue/<kernel>/out
  bool image;
  std::chrono::nanoseconds period;
};

/// `cameras` 30 Hz image streams (cam0, cam1, ...) and the 1 kHz Bool stream (flag).
inline std::vector<Stream> streams(int cameras = 4) {
  using namespace std::chrono_literals;
  const auto frame = std::chrono::nanoseconds(1'000'000'000 / 30);
  std::vector<Stream> out;
  for (int i = 0; i < cameras; ++i) out.push_back({"cam" + std::to_string(i), true, frame});
  out.push_back({"flag", false, 1ms});
  return out;
}

/// The 768x576 grey image every camera stream sends (seed 004's PAL frame).
inline GvImage pal_image() {
  GvImage g;
  g.dx(768);
  g.dy(576);
  g.image().resize(768u * 576u);
  for (std::size_t k = 0; k < g.image().size(); ++k) {
    g.image()[k] = static_cast<std::uint8_t>((k % 768 + k / 768) & 0xff);
  }
  return g;
}

/// The folder of this program (the other oscar programs lie beside it).
inline std::filesystem::path own_dir() {
  return std::filesystem::read_symlink("/proc/self/exe").parent_path();
}

using test::cpu_seconds;  // process_cpu.hpp (tests/common)

inline std::uint64_t wall_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

}  // namespace oscar::bench
