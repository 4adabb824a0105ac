#pragma once
// Internal: how many configuration commands each writer may send a module (a token bucket per
// writer). A process that floods a module's configuration topic has its excess dropped before
// it is queued, so the commands of other writers are still applied and answered in time.
// Writers are told apart by their DDS participant; the `writers` heard from last are tracked (a
// writer forgotten and heard again starts with a full bucket: the module's queue bound, not this
// table, caps what many writers together can queue).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <list>
#include <optional>
#include <string>
#include <unordered_map>

namespace oscar::internal {

class CommandRateLimit {
 public:
  using Clock = std::chrono::steady_clock;
  /// A writer may send `burst` commands at once and `per_second` on average.
  struct Rate {
    double per_second = 0;
    double burst = 0;
  };
  /// Far above what boot, the registry and the coordinator send a module (a handful of commands
  /// per kernel at boot or restart, each waiting for its reply), far below a flood.
  static constexpr Rate kDefaultRate{100, 200};
  static constexpr std::size_t kDefaultWriters = 64;

  explicit CommandRateLimit(Rate rate = kDefaultRate, std::size_t writers = kDefaultWriters);

  /// True if `writer` may send one more command at `now`; false if it is over its rate (the
  /// command is counted as dropped).
  bool admit(const std::string& writer, Clock::time_point now);
  /// A log line naming the writers whose commands were dropped since the last line, and how
  /// many; at most one per `every`, none while nothing was dropped.
  std::optional<std::string> report(Clock::time_point now,
                                    Clock::duration every = std::chrono::seconds(1));
  /// Commands dropped since construction.
  std::uint64_t dropped() const { return dropped_; }
  /// Writers tracked now (at most `writers`).
  std::size_t tracked() const { return by_writer_.size(); }

 private:
  struct Bucket {
    std::string writer;
    double tokens = 0;
    Clock::time_point refilled{};
    std::uint64_t dropped_unreported = 0;
  };
  Rate rate_;
  std::size_t capacity_;
  std::list<Bucket> recent_;  // heard from last first
  std::unordered_map<std::string, std::list<Bucket>::iterator> by_writer_;
  std::uint64_t dropped_ = 0;
  std::uint64_t unreported_ = 0;
  std::uint64_t reported_from_forgotten_ = 0;  // drops of writers forgotten before the report
  std::optional<Clock::time_point> last_report_;
};

}  // namespace oscar::internal
