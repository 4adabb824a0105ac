#include "conversion_worker.hpp"

#include <exception>

namespace oscar::bridge {

ConversionWorker::ConversionWorker(Convert convert, Done done)
    : convert_(std::move(convert)), done_(std::move(done)), thread_([this] { run(); }) {}

ConversionWorker::~ConversionWorker() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

bool ConversionWorker::submit(Job job) {
  bool replaced = false;
  {
    std::lock_guard lock(mutex_);
    const auto channel = job.channel;
    replaced = !waiting_.insert_or_assign(channel, std::move(job)).second;
  }
  wake_.notify_one();
  return replaced;
}

void ConversionWorker::run() {
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !waiting_.empty(); });
      if (stopping_) return;
      auto it = waiting_.lower_bound(next_channel_);
      if (it == waiting_.end()) it = waiting_.begin();
      job = std::move(it->second);
      waiting_.erase(it);
      next_channel_ = job.channel + 1;
    }
    Result result{.channel = job.channel, .receive_ns = job.receive_ns, .message = {}, .error = {}};
    try {
      result.message = convert_(job);
    } catch (const std::exception& e) {
      result.error = e.what();
      if (result.error.empty()) result.error = "conversion failed";
    }
    done_(std::move(result));
  }
}

}  // namespace oscar::bridge
