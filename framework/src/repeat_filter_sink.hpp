#pragma once
// An spdlog sink in front of a module's sinks that lets a line repeated by the same logger
// through at most once per `window`, with how often it came meanwhile: a kernel that fails every
// cycle (a missing camera at 10 Hz) writes one line a second, not ten, and says how many it
// held back. Lines are the same when logger, level and text are; distinct lines interleave
// freely (two failing kernels do not reset each other's count).

#include <chrono>
#include <map>
#include <mutex>
#include <string>
#include <tuple>

#include <fmt/format.h>
#include <spdlog/details/log_msg.h>
#include <spdlog/sinks/dist_sink.h>

namespace oscar::internal {

class RepeatFilterSink final : public spdlog::sinks::dist_sink<std::mutex> {
 public:
  explicit RepeatFilterSink(std::chrono::milliseconds window) : window_(window) {}

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    Key key{std::string(msg.logger_name.begin(), msg.logger_name.end()), msg.level,
            std::string(msg.payload.begin(), msg.payload.end())};
    auto it = seen_.find(key);
    if (it != seen_.end() && msg.time - it->second.shown < window_) {
      ++it->second.held_back;
      return;
    }
    if (it == seen_.end()) {
      if (seen_.size() >= kMaxLines) forget_old(msg.time);
      it = seen_.emplace(std::move(key), Seen{}).first;
    }
    if (it->second.held_back == 0) {
      dist_sink::sink_it_(msg);
    } else {
      const auto text =
          fmt::format("{} ({} more times in the last {:.1f} s)", msg.payload, it->second.held_back,
                      std::chrono::duration<double>(msg.time - it->second.shown).count());
      spdlog::details::log_msg counted(msg.time, msg.source, msg.logger_name, msg.level, text);
      dist_sink::sink_it_(counted);
    }
    it->second = Seen{msg.time, 0};
  }

 private:
  using Key = std::tuple<std::string, spdlog::level::level_enum, std::string>;
  struct Seen {
    spdlog::log_clock::time_point shown{};
    std::uint64_t held_back = 0;
  };
  static constexpr std::size_t kMaxLines = 256;

  // Lines shown before the window with nothing held back can go: they would be shown anyway.
  void forget_old(spdlog::log_clock::time_point now) {
    std::erase_if(seen_, [&](const auto& kv) {
      return kv.second.held_back == 0 && now - kv.second.shown >= window_;
    });
    if (seen_.size() >= kMaxLines) seen_.clear();
  }

  std::chrono::milliseconds window_;
  std::map<Key, Seen> seen_;
};

}  // namespace oscar::internal
