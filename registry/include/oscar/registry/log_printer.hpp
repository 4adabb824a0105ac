#pragma once
/// @file LogPrinter: the merged log of a system (oscar/log), time-ordered across modules, one
/// colour per module on a terminal. Used by `oscar boot` and `oscar log`.

#include <cstdio>
#include <map>
#include <mutex>
#include <string>

#include <oscar/config.h>

namespace oscar {

class LogPrinter {
 public:
  /// Lines are held back `delay_ns` so that records from several hosts come out in time order.
  explicit LogPrinter(std::FILE* out, bool colour, unsigned long long delay_ns = 200'000'000);
  void add(const LogRecord& record);
  /// A line of the printer's own ("boot", "registry"), ordered with the rest.
  void note(const std::string& who, const std::string& message, LogLevel level = LOG_INFO);
  /// Prints what is older than the delay (everything if `all`).
  void flush(bool all = false);

 private:
  std::string format(const LogRecord& r);
  std::FILE* out_;
  bool colour_;
  unsigned long long delay_ns_;
  std::mutex mutex_;
  std::multimap<unsigned long long, LogRecord> pending_;
  std::map<std::string, int> colours_;
};

}  // namespace oscar
