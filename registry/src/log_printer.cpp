#include "oscar/registry/log_printer.hpp"

#include <ctime>

#include <fmt/format.h>

#include "oscar/time.hpp"

namespace oscar {
namespace {
// As a module's own output names them (spdlog's names): one word for a level everywhere.
const char* level_name(LogLevel l) {
  switch (l) {
    case LOG_TRACE:
      return "trace";
    case LOG_DEBUG:
      return "debug";
    case LOG_INFO:
      return "info ";
    case LOG_WARN:
      return "warning";
    case LOG_ERROR:
      return "error";
    case LOG_CRITICAL:
      return "critical";
  }
  return "?";
}
}  // namespace

LogPrinter::LogPrinter(std::FILE* out, bool colour, unsigned long long delay_ns)
    : out_(out), colour_(colour), delay_ns_(delay_ns) {}

void LogPrinter::add(const LogRecord& record) {
  std::lock_guard lock(mutex_);
  pending_.emplace(corrected_stamp(record), record);
}

unsigned long long LogPrinter::corrected_stamp(const LogRecord& record) const {
  const auto host = module_hosts_.find(record.module_name());
  if (host == module_hosts_.end()) return record.stamp_ns();
  const auto offset = host_offsets_.find(host->second);
  if (offset == host_offsets_.end()) return record.stamp_ns();
  return record.stamp_ns() - static_cast<unsigned long long>(offset->second.count());
}

void LogPrinter::module_host(const std::string& module, const std::string& host) {
  std::lock_guard lock(mutex_);
  module_hosts_[module] = host;
}

void LogPrinter::host_clock(const std::string& host, std::chrono::nanoseconds offset,
                            std::chrono::nanoseconds uncertainty) {
  {
    std::lock_guard lock(mutex_);
    const auto [it, first] = host_offsets_.emplace(host, offset);
    if (first || it->second != offset) {
      it->second = offset;
      // Records held back were ordered by what was known when they came (the first ones of a
      // host often come before its first estimate): order them again.
      std::multimap<unsigned long long, LogRecord> reordered;
      for (auto& [stamp, r] : pending_) reordered.emplace(corrected_stamp(r), std::move(r));
      pending_.swap(reordered);
    }
    if (std::chrono::abs(offset) <= kClockWarning || !hosts_warned_.insert(host).second) return;
  }
  note("clocks",
       fmt::format("host {}'s clock is {:+.1f} ms (± {:.1f} ms) from the registry's: the merged "
                   "log orders its records by corrected time, but cue stamps stay off; keep the "
                   "hosts in sync with chrony or PTP (docs/boot.md, \"Clocks\")",
                   host, std::chrono::duration<double, std::milli>(offset).count(),
                   std::chrono::duration<double, std::milli>(uncertainty).count()),
       LOG_WARN);
}

void LogPrinter::note(const std::string& who, const std::string& message, LogLevel level) {
  LogRecord r;
  r.stamp_ns(static_cast<unsigned long long>(wall_now()));
  r.module_name(who);
  r.level(level);
  r.message(message);
  add(r);
}

std::string LogPrinter::format(const LogRecord& r) {
  const auto secs = static_cast<std::time_t>(r.stamp_ns() / 1'000'000'000ULL);
  std::tm tm{};
  localtime_r(&secs, &tm);
  const auto ms = (r.stamp_ns() / 1'000'000ULL) % 1000;
  const auto who = r.kernel().empty() || r.kernel() == r.module_name()
                       ? r.module_name()
                       : r.module_name() + "/" + r.kernel();
  if (!colour_) {
    return fmt::format("{:02}:{:02}:{:02}.{:03} {} [{}] {}\n", tm.tm_hour, tm.tm_min, tm.tm_sec, ms,
                       level_name(r.level()), who, r.message());
  }
  static constexpr int kPalette[] = {36, 32, 33, 35, 34, 96, 92, 93, 95, 94};
  const auto [it, added] = colours_.emplace(r.module_name(), 0);
  if (added) it->second = kPalette[(colours_.size() - 1) % std::size(kPalette)];
  const int level_colour = r.level() >= LOG_ERROR ? 31 : r.level() == LOG_WARN ? 33 : 0;
  return fmt::format("{:02}:{:02}:{:02}.{:03} \x1b[{}m{}\x1b[0m \x1b[{}m[{}]\x1b[0m {}\n",
                     tm.tm_hour, tm.tm_min, tm.tm_sec, ms, level_colour, level_name(r.level()),
                     it->second, who, r.message());
}

void LogPrinter::flush(bool all) {
  std::lock_guard lock(mutex_);
  const auto horizon = static_cast<unsigned long long>(wall_now()) - delay_ns_;
  while (!pending_.empty() && (all || pending_.begin()->first <= horizon)) {
    auto& [stamp, record] = *pending_.begin();
    record.stamp_ns(stamp);  // the corrected time
    std::fputs(format(record).c_str(), out_);
    pending_.erase(pending_.begin());
  }
  std::fflush(out_);
}

}  // namespace oscar
