#include "oscar/malformed_samples.hpp"

#include <chrono>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <fastdds/dds/topic/TopicDescription.hpp>

namespace oscar {
namespace {
using Clock = std::chrono::steady_clock;
constexpr auto kReportEvery = std::chrono::seconds(10);
constexpr std::string_view kTypeKey = "type ";  // counts kept by type, not topic

struct Refused {
  std::string type, why;
};

// The take_next() under way on this thread: the topic it reads and what the type support
// refused meanwhile. Logged after the take, since logging may write on oscar/log, and Fast DDS
// holds the reader's lock while it decodes.
struct Reading {
  const std::string& topic;
  std::vector<Refused> refused;
};
thread_local Reading* reading = nullptr;

class Counts {
 public:
  void record(const std::string& key, const Refused& r) {
    std::shared_ptr<spdlog::logger> log;
    std::uint64_t total = 0, since = 0;
    Clock::duration quiet{};
    {
      std::lock_guard lock(mutex_);
      auto& c = topics_[key];
      total = ++c.total;
      ++c.unreported;
      const auto now = Clock::now();
      quiet = now - c.reported;
      if (total > 1 && quiet < kReportEvery) return;  // counted; reported with the next line
      since = std::exchange(c.unreported, 0);
      c.reported = now;
      log = log_ ? log_ : spdlog::default_logger();
    }
    // Where the topic is not known (a type support used outside take_next()), the type is.
    const auto where = key.starts_with(kTypeKey) ? fmt::format("of type {}", r.type)
                                                 : fmt::format("on {} ({})", key, r.type);
    if (total == 1) {
      log->warn(
          "dropped a malformed sample {}: {}; more like it are counted and reported at most "
          "every {} s",
          where, r.why, kReportEvery.count());
    } else {
      log->warn("dropped {} malformed samples {} in the last {} s, {} in all; the last: {}", since,
                where, std::chrono::duration_cast<std::chrono::seconds>(quiet).count(), total,
                r.why);
    }
  }
  std::uint64_t total(const std::string& topic) const {
    std::lock_guard lock(mutex_);
    const auto it = topics_.find(topic);
    return it == topics_.end() ? 0 : it->second.total;
  }
  void set_log(std::shared_ptr<spdlog::logger> log) {
    std::lock_guard lock(mutex_);
    log_ = std::move(log);
  }

 private:
  struct Topic {
    std::uint64_t total = 0;
    std::uint64_t unreported = 0;  // since the last line
    Clock::time_point reported{};
  };
  mutable std::mutex mutex_;
  std::map<std::string, Topic> topics_;
  std::shared_ptr<spdlog::logger> log_;
};

Counts& counts() {
  static Counts c;
  return c;
}

}  // namespace

eprosima::fastrtps::types::ReturnCode_t take_next(eprosima::fastdds::dds::DataReader& reader,
                                                  void* data,
                                                  eprosima::fastdds::dds::SampleInfo& info) {
  Reading here{reader.get_topicdescription()->get_name(), {}};
  eprosima::fastrtps::types::ReturnCode_t result;
  {
    // Restored however the take ends: `here` must not outlive its use.
    struct Restore {
      Reading* outer;
      ~Restore() { reading = outer; }
    } restore{std::exchange(reading, &here)};
    result = reader.take_next_sample(data, &info);
  }
  for (const auto& r : here.refused) counts().record(here.topic, r);
  return result;
}

std::uint64_t malformed_sample_count(const std::string& topic) { return counts().total(topic); }

void set_malformed_sample_log(std::shared_ptr<spdlog::logger> log) {
  counts().set_log(std::move(log));
}

void internal::note_malformed_sample(std::string_view type, std::string_view why) {
  Refused r{std::string(type), std::string(why)};
  if (reading) {
    reading->refused.push_back(std::move(r));
  } else {
    counts().record(std::string(kTypeKey) + r.type, r);
  }
}

}  // namespace oscar
