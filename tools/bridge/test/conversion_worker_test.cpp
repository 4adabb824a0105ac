#include "conversion_worker.hpp"

#include <atomic>
#include <chrono>
#include <stdexcept>

#include <gtest/gtest.h>

namespace oscar::bridge {
namespace {
using namespace std::chrono_literals;

// What the worker handed back, for the test thread to wait on.
struct Results {
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<ConversionWorker::Result> list;

  void add(ConversionWorker::Result r) {
    std::lock_guard lock(mutex);
    list.push_back(std::move(r));
    changed.notify_all();
  }
  // Waits (generously: sanitizer builds are slow) until there are `n`.
  bool wait_for(std::size_t n) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, 30s, [&] { return list.size() >= n; });
  }
};

ConversionWorker::Job job(std::uint32_t channel, std::uint64_t stamp) {
  return {.channel = channel,
          .source_type = "oscar::GvImage",
          .schema_name = "foxglove.RawImage",
          .cdr = std::make_shared<const std::vector<std::uint8_t>>(),
          .receive_ns = stamp};
}

TEST(ConversionWorker, ASlowConversionDoesNotHoldUpWhoSubmitsAndTheNewestSampleWins) {
  std::mutex gate;  // held by the test: the conversion under way waits on it
  std::unique_lock closed(gate);
  std::atomic<int> started{0};
  Results results;
  ConversionWorker worker(
      [&](const ConversionWorker::Job& j) -> std::optional<std::string> {
        ++started;
        std::lock_guard wait(gate);
        return std::to_string(j.receive_ns);
      },
      [&](ConversionWorker::Result r) { results.add(std::move(r)); });
  EXPECT_FALSE(worker.submit(job(1, 1)));
  while (started == 0) std::this_thread::sleep_for(1ms);
  // The conversion of sample 1 is stuck; submitting returns at once, and of the samples that
  // wait, the newest of each channel wins.
  int replaced = 0;
  for (std::uint64_t stamp = 2; stamp <= 100; ++stamp) replaced += worker.submit(job(1, stamp));
  EXPECT_FALSE(worker.submit(job(2, 7)));
  EXPECT_EQ(replaced, 98) << "samples 2 to 99 were replaced before they started";
  closed.unlock();
  ASSERT_TRUE(results.wait_for(3));
  std::this_thread::sleep_for(50ms);
  std::lock_guard lock(results.mutex);
  ASSERT_EQ(results.list.size(), 3u);
  EXPECT_EQ(results.list[0].message, "1");
  EXPECT_EQ(results.list[1].channel, 2u) << "round robin: channel 2 comes after channel 1";
  EXPECT_EQ(results.list[2].message, "100");
}

TEST(ConversionWorker, AFailedConversionIsAResultNamingWhy) {
  Results results;
  ConversionWorker worker(
      [](const ConversionWorker::Job&) -> std::optional<std::string> {
        throw std::runtime_error("malformed oscar::GvImage");
      },
      [&](ConversionWorker::Result r) { results.add(std::move(r)); });
  worker.submit(job(3, 42));
  ASSERT_TRUE(results.wait_for(1));
  std::lock_guard lock(results.mutex);
  EXPECT_EQ(results.list[0].channel, 3u);
  EXPECT_EQ(results.list[0].receive_ns, 42u);
  EXPECT_FALSE(results.list[0].message);
  EXPECT_EQ(results.list[0].error, "malformed oscar::GvImage");
}

}  // namespace
}  // namespace oscar::bridge
