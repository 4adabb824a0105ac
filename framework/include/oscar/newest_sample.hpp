#pragma once
/// @file A command-line tool's one look at a topic: its newest sample, and whether anyone
/// publishes it.

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>

#include "oscar/dds_participant.hpp"
#include "oscar/topic_io.hpp"

namespace oscar {

/// What a tool's one look at a topic found (newest_sample()).
template <class T>
struct NewestSample {
  std::optional<T> sample;    ///< none if nothing came
  bool writer_found = false;  ///< a writer of the topic was discovered
};

/// The newest sample of a topic whose writer keeps it for late readers (transient local) or
/// writes it periodically, as a command-line tool reads it once. Waits up to `wait`; a writer
/// found by then gets as long again to deliver it (on a loaded host discovery and a large
/// sample take their time), so that a tool can tell "nobody publishes it" from "the publisher
/// sends nothing".
template <class T, class PubSubType>
NewestSample<T> newest_sample(DdsParticipant& participant, const TopicSpec<T, PubSubType>& spec,
                              std::chrono::milliseconds wait) {
  std::mutex mutex;
  std::condition_variable arrived;
  NewestSample<T> found;
  TopicReader<T, PubSubType> reader(participant, spec, [&](const T& sample, const auto&) {
    std::lock_guard lock(mutex);
    found.sample = sample;
    arrived.notify_all();
  });
  std::unique_lock lock(mutex);  // released before the reader goes (its callback takes it)
  const auto has_sample = [&] { return found.sample.has_value(); };
  if (!arrived.wait_for(lock, wait, has_sample) && reader.matched() > 0) {
    arrived.wait_for(lock, wait, has_sample);
  }
  found.writer_found = found.sample.has_value() || reader.matched() > 0;
  return found;
}

}  // namespace oscar
