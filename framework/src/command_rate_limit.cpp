#include "command_rate_limit.hpp"

#include <algorithm>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oscar/demand.hpp"

namespace oscar::internal {

CommandRateLimit::CommandRateLimit(Rate rate, std::size_t writers)
    : rate_(rate), capacity_(writers) {
  OSCAR_DEMAND(rate_.per_second > 0 && rate_.burst >= 1 && capacity_ > 0,
               "a command rate limit lets at least one command of one writer through");
}

bool CommandRateLimit::admit(const std::string& writer, Clock::time_point now) {
  auto it = by_writer_.find(writer);
  if (it == by_writer_.end()) {
    if (by_writer_.size() >= capacity_) {
      reported_from_forgotten_ += recent_.back().dropped_unreported;
      by_writer_.erase(recent_.back().writer);
      recent_.pop_back();
    }
    recent_.push_front({writer, rate_.burst, now, 0});
    it = by_writer_.emplace(writer, recent_.begin()).first;
  } else {
    recent_.splice(recent_.begin(), recent_, it->second);
  }
  auto& b = *it->second;
  const double elapsed_s = std::chrono::duration<double>(now - b.refilled).count();
  if (elapsed_s > 0) {
    b.tokens = std::min(rate_.burst, b.tokens + elapsed_s * rate_.per_second);
    b.refilled = now;
  }
  if (b.tokens >= 1) {
    b.tokens -= 1;
    return true;
  }
  ++b.dropped_unreported;
  ++dropped_;
  ++unreported_;
  return false;
}

std::optional<std::string> CommandRateLimit::report(Clock::time_point now, Clock::duration every) {
  if (unreported_ == 0 || (last_report_ && now - *last_report_ < every)) return std::nullopt;
  std::vector<std::string> writers;
  for (auto& b : recent_) {
    if (b.dropped_unreported == 0) continue;
    writers.push_back(fmt::format("{} from writer {}", b.dropped_unreported, b.writer));
    b.dropped_unreported = 0;
  }
  if (reported_from_forgotten_ > 0) {
    writers.push_back(fmt::format("{} from writers no longer tracked", reported_from_forgotten_));
  }
  auto line = fmt::format(
      "dropped {} configuration command(s) over the rate limit of {}/s (burst {}) per writer: {}",
      unreported_, rate_.per_second, rate_.burst, fmt::join(writers, ", "));
  unreported_ = 0;
  reported_from_forgotten_ = 0;
  last_report_ = now;
  return line;
}

}  // namespace oscar::internal
