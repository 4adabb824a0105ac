#pragma once
// An spdlog sink that publishes every log line as a LogRecord on oscar/log (module, kernel,
// level, time). Until the module joins DDS (and after it leaves) it drops records silently;
// the console sink beside it still prints them.

#include <atomic>
#include <cstdlib>
#include <mutex>
#include <string>

#include <oscar/config.h>
#include <spdlog/sinks/base_sink.h>
#include <fastdds/dds/publisher/DataWriter.hpp>

namespace oscar::internal {

class DdsLogSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit DdsLogSink(std::string module)
      : module_(std::move(module)), test_clock_offset_ns_(test_clock_offset_ns()) {}
  void attach(eprosima::fastdds::dds::DataWriter* writer) {
    std::lock_guard lock(mutex_);
    writer_ = writer;
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    if (!writer_) return;
    LogRecord r;
    r.stamp_ns(static_cast<unsigned long long>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(msg.time.time_since_epoch()).count() +
        test_clock_offset_ns_));
    r.module_name(module_);
    const std::string logger(msg.logger_name.begin(), msg.logger_name.end());
    const auto slash = logger.find('/');
    r.kernel(slash == std::string::npos ? "" : logger.substr(slash + 1));
    r.level(static_cast<LogLevel>(std::min<int>(msg.level, LOG_CRITICAL)));
    r.message(std::string(msg.payload.begin(), msg.payload.end()));
    writer_->write(&r);
  }
  void flush_() override {}

 private:
  // The test hook OSCAR_CLOCK_OFFSET_MS (docs/boot.md, "Clocks"), for tests only: a test that
  // fakes a host whose clock is off sets it for that host's monitor, whose modules inherit it,
  // so their records are stamped as on that host. The monitor rejects a malformed value.
  static long long test_clock_offset_ns() {
    const char* ms = std::getenv("OSCAR_CLOCK_OFFSET_MS");
    return ms == nullptr ? 0 : std::strtoll(ms, nullptr, 10) * 1'000'000;
  }

  std::string module_;
  long long test_clock_offset_ns_ = 0;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;  // guarded by base_sink's mutex_
};

}  // namespace oscar::internal
