#pragma once
// ConversionWorker: makes side channel messages (CDR decoding, JPEG, base64, JSON) on a thread
// of its own, so the bridge's I/O thread, which forwards every raw channel, never waits for an
// encoder (docs/foxglove.md, "Side channels"). At most one sample per side channel waits: a
// newer one replaces it (newest wins; the replaced one is skipped), so a slow encoder costs its
// own channel frames and nothing else.

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace oscar::bridge {

class ConversionWorker {
 public:
  struct Job {
    std::uint32_t channel = 0;  ///< the side channel
    std::string source_type;    ///< IDL type of the sample
    std::string schema_name;    ///< the side channel's schema
    std::shared_ptr<const std::vector<std::uint8_t>> cdr;
    std::uint64_t receive_ns = 0;
  };
  struct Result {
    std::uint32_t channel = 0;
    std::uint64_t receive_ns = 0;
    std::optional<std::string> message;  ///< nullopt: nothing to draw, or `error`
    std::string error;                   ///< why the conversion failed ("" if it did not)
  };
  /// Makes the message of a job; may throw (the exception's text becomes Result::error).
  using Convert = std::function<std::optional<std::string>(const Job&)>;
  /// Called on the worker's thread with each result.
  using Done = std::function<void(Result)>;

  ConversionWorker(Convert convert, Done done);
  /// Stops after the conversion under way; jobs still waiting are dropped.
  ~ConversionWorker();
  ConversionWorker(const ConversionWorker&) = delete;
  ConversionWorker& operator=(const ConversionWorker&) = delete;

  /// Queues `job` for its channel. Returns true if it replaced a job of that channel that had
  /// not started (that sample is skipped, the caller counts it).
  bool submit(Job job);

 private:
  void run();

  Convert convert_;
  Done done_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::map<std::uint32_t, Job> waiting_;  // by channel: the newest sample of each
  std::uint32_t next_channel_ = 0;        // round robin: no channel starves another
  bool stopping_ = false;
  std::thread thread_;  // last: starts once the members above exist
};

}  // namespace oscar::bridge
