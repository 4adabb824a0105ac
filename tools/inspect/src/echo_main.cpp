// oscar echo TOPIC: every sample of a topic, readably (YAML-like), decoded from its CDR with the
// type's IDL (the embedded OSCAR IDL texts, or the text the producing module announces for a type
// of its own), headers with seq, source and stamps.
#include <atomic>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <deque>
#include <mutex>
#include <set>

#include <fmt/format.h>

#include <oscar/command_line.hpp>
#include "idl_types.hpp"
#include "oscar/idl_texts.hpp"
#include "oscar/type_texts.hpp"

#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/system_options.hpp"
#include "raw_tap.hpp"
#include "recorder.hpp"  // topic_of

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar echo: print the samples of a topic readably"};
  oscar::SystemOptions tool;
  tool.add_to(app);
  std::string topic_arg;
  long count = 0;
  double timeout_s = 5;
  std::size_t max_items = 16;
  app.add_option("TOPIC", topic_arg, "kernel/channel (the cue topic) or a full topic name")
      ->required();
  app.add_option("-n,--count", count, "exit after this many samples (0: until Ctrl-C)");
  app.add_option("--timeout", timeout_s, "seconds to wait for a writer of the topic");
  app.add_option("--max-items", max_items, "items shown of a long sequence");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    const auto topic = oscar::record::topic_of(topic_arg);
    oscar::inspect::IdlTypes types;
    std::set<std::string> texts;
    for (const auto& [name, text] : oscar::idl_texts()) {
      if (texts.insert(text).second) types.add(text);
    }
    auto participant = tool.participant("oscar-echo");
    const oscar::AnnouncedTypes announced(*participant);
    const auto type = oscar::inspect::wait_for_writer(
        *participant, topic, std::chrono::milliseconds(static_cast<long>(timeout_s * 1000)));
    if (type.empty()) {
      fmt::print(stderr,
                 "oscar echo: no writer of topic '{}' appeared on domain {} within {} s{}\n", topic,
                 participant->domain(), timeout_s, oscar::where_systems_run(participant->domain()));
      return 1;
    }
    if (!types.has(type)) {
      if (const auto text = announced.wait_for(type, std::chrono::seconds(2))) types.add(*text);
    }
    if (!types.has(type)) {
      fmt::print(stderr,
                 "oscar echo: topic '{}' has type '{}', whose IDL is unknown here: OSCAR does not "
                 "define it and no module announced its IDL text (a module built with "
                 "oscar_add_module(... IDL ...) does)\n",
                 topic, type);
      return 1;
    }
    std::mutex mutex;
    std::condition_variable cv;
    std::deque<std::pair<std::vector<std::uint8_t>, std::uint64_t>> queue;
    oscar::inspect::RawTap tap(*participant, [&](const std::string&, auto bytes, auto t) {
      std::lock_guard lock(mutex);
      queue.emplace_back(std::move(bytes), t);
      cv.notify_one();
    });
    tap.subscribe(topic);
    const oscar::inspect::IdlTypes::Options options{max_items};
    long shown = 0;
    while (!g_stop && (count == 0 || shown < count)) {
      std::unique_lock lock(mutex);
      cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return !queue.empty(); });
      while (!queue.empty() && (count == 0 || shown < count)) {
        auto [bytes, received] = std::move(queue.front());
        queue.pop_front();
        lock.unlock();
        std::string text;
        try {
          text = types.to_text(type, bytes, options);
        } catch (const std::exception& e) {
          text = fmt::format("# cannot decode {} bytes: {}", bytes.size(), e.what());
        }
        fmt::print("--- {} ({}) received {}\n{}\n", topic, type, oscar::inspect::utc_text(received),
                   text);
        std::fflush(stdout);
        ++shown;
        lock.lock();
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar echo: %s\n", e.what());
    return 1;
  }
}
