#pragma once
// Recorder: subscribes to cue topics as discovery finds their writers, keeps each sample's
// serialized bytes and writes them to MCAP files (docs/recording.md), splitting by size or
// duration.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "oscar/mcap/records.hpp"

namespace oscar::record {

struct RecorderOptions {
  std::string output = "oscar.mcap";
  /// Topics or globs; a name without "oscar/" means the cue topic "oscar/cue/<name>".
  std::vector<std::string> topics;
  bool all = false;  ///< every cue topic (oscar/cue/*)
  mcap::Compression compression = mcap::Compression::kZstd;
  std::size_t chunk_size_bytes = 1 << 20;
  /// A chunk that is this old is written even if not full: what a killed recorder can lose.
  std::chrono::milliseconds max_chunk_age{1000};
  std::uint64_t split_size_bytes = 0;          ///< 0 = no split by size
  std::chrono::nanoseconds split_duration{0};  ///< 0 = no split by time
  int domain = 0;
  bool progress = false;  ///< a progress line on stderr
};

struct RecorderCounters {
  std::uint64_t received = 0;
  std::uint64_t written = 0;
  std::uint64_t dropped = 0;
  std::uint64_t bytes = 0;  ///< payload bytes written
};

class Recorder {
 public:
  /// Joins the domain and creates the first file.
  /// @throws std::invalid_argument for bad options; std::runtime_error if the file cannot be
  ///         created (naming it).
  explicit Recorder(RecorderOptions options);
  ~Recorder();
  /// Records until `stop` is set, then writes what was received and finishes the file.
  void run(const std::atomic<bool>& stop);
  RecorderCounters counters() const;
  /// The files written so far (several when splitting).
  const std::vector<std::string>& files() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The DDS topic a TOPIC argument names: "src/out" -> "oscar/cue/src/out"; "oscar/..." as is.
std::string topic_of(const std::string& argument);

}  // namespace oscar::record
