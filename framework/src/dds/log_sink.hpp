#pragma once
// An spdlog sink that publishes every log line as a LogRecord on oscar/log (module, kernel,
// level, time). Until the module joins DDS (and after it leaves) it drops records silently;
// the console sink beside it still prints them.

#include <atomic>
#include <mutex>
#include <string>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <oscar/config.h>
#include <spdlog/sinks/base_sink.h>

namespace oscar::internal {

class DdsLogSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit DdsLogSink(std::string module) : module_(std::move(module)) {}
  void attach(eprosima::fastdds::dds::DataWriter* writer) {
    std::lock_guard lock(mutex_);
    writer_ = writer;
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    if (!writer_) return;
    LogRecord r;
    r.stamp_ns(static_cast<unsigned long long>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(msg.time.time_since_epoch()).count()));
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
  std::string module_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;  // guarded by base_sink's mutex_
};

}  // namespace oscar::internal
