#pragma once
// Replayer: publishes the messages of an MCAP recording on their topics with the original
// relative timing (scaled by a rate), as the raw CDR they were recorded as, so the cues keep
// their original headers; docs/recording.md.

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace oscar::replay {

struct ReplayOptions {
  std::string file;
  double rate = 1.0;  ///< 2 = twice as fast
  bool loop = false;
  std::optional<std::chrono::nanoseconds> start, end;  ///< from the recording's first message
  std::vector<std::string> topics;                     ///< topics or globs; empty = all
  std::map<std::string, std::string> remap;            ///< recorded topic -> published topic
  bool step = false;                                   ///< wait for Enter before each message
  std::chrono::milliseconds wait_for_readers{2000};
  int domain = 0;
  bool progress = false;
};

struct ReplayCounters {
  std::uint64_t published = 0;
  std::uint64_t topics = 0;
  double seconds = 0;
  double late_us_p50 = 0, late_us_p99 = 0, late_us_max = 0;  ///< publishing against the schedule
};

/// Validates the options and the file, joins the domain and creates a writer per topic.
/// @throws std::invalid_argument for bad options or a topic that carries another type in the
///         running system; mcap::FormatError for a corrupt file.
class Replayer {
 public:
  explicit Replayer(ReplayOptions options);
  ~Replayer();
  /// Publishes until the recording ends (or, with loop, until `stop`).
  ReplayCounters run(const std::atomic<bool>& stop);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace oscar::replay
