#pragma once
/// @file LogPrinter: the merged log of a system (oscar/log), time-ordered across modules, one
/// colour per module on a terminal. Used by `oscar boot` and `oscar log`.

#include <chrono>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>
#include <string>

#include <oscar/config.h>

namespace oscar {

class LogPrinter {
 public:
  /// Lines are held back `delay_ns` so that records from several hosts come out in time order.
  explicit LogPrinter(std::FILE* out, bool colour, unsigned long long delay_ns = 200'000'000);
  /// Orders a record by its stamp minus its host's clock offset, when the printer knows both
  /// (module_host, host_clock), and prints it with that corrected time.
  void add(const LogRecord& record);
  /// `module` runs on `host`.
  void module_host(const std::string& module, const std::string& host);
  /// The latest estimate of how far `host`'s clock is ahead of the registry's (docs/boot.md,
  /// "Clocks"); the records held back are ordered again. Says once per host when it is more
  /// than kClockWarning off.
  void host_clock(const std::string& host, std::chrono::nanoseconds offset,
                  std::chrono::nanoseconds uncertainty);
  static constexpr std::chrono::milliseconds kClockWarning{10};
  /// A line of the printer's own ("boot", "registry"), ordered with the rest.
  void note(const std::string& who, const std::string& message, LogLevel level = LOG_INFO);
  /// Prints what is older than the delay (everything if `all`).
  void flush(bool all = false);

 private:
  std::string format(const LogRecord& r);
  /// The record's stamp minus its host's offset, where both are known (mutex_ held).
  unsigned long long corrected_stamp(const LogRecord& record) const;
  std::FILE* out_;
  bool colour_;
  unsigned long long delay_ns_;
  std::mutex mutex_;
  std::multimap<unsigned long long, LogRecord> pending_;
  std::map<std::string, int> colours_;
  std::map<std::string, std::string> module_hosts_;
  std::map<std::string, std::chrono::nanoseconds> host_offsets_;
  std::set<std::string> hosts_warned_;
};

}  // namespace oscar
