#include "raw_tap.hpp"

#include <chrono>
#include <map>
#include <mutex>
#include <thread>

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include "oscar/malformed_samples.hpp"
#include "oscar/raw_cdr_type.hpp"

namespace oscar::inspect {
namespace dds = eprosima::fastdds::dds;

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

struct RawTap::Impl {
  class Listener final : public dds::DataReaderListener {
   public:
    Listener(const Fn& fn, std::string topic) : fn_(fn), topic_(std::move(topic)) {}
    void on_data_available(dds::DataReader* reader) override {
      RawCue s;
      dds::SampleInfo info;
      while (take_next(*reader, &s, info) == ReturnCode_t::RETCODE_OK) {
        if (info.valid_data) fn_(topic_, std::move(s.cdr), now_ns());
      }
    }

   private:
    const Fn& fn_;
    std::string topic_;
  };
  DdsParticipant& participant;
  Fn fn;
  std::mutex mutex;
  std::map<std::string, std::pair<std::string, dds::DataReader*>> readers;  // topic -> type
  // One per topic ever subscribed, kept until the tap goes: a reader being deleted may still be
  // in its listener on a Fast DDS thread.
  std::map<std::string, std::unique_ptr<Listener>> listeners;
  Impl(DdsParticipant& p, Fn f) : participant(p), fn(std::move(f)) {}
};

RawTap::RawTap(DdsParticipant& participant, Fn fn)
    : impl_(std::make_unique<Impl>(participant, std::move(fn))) {}

RawTap::~RawTap() {
  for (auto& [topic, r] : impl_->readers)
    impl_->participant.subscriber().delete_datareader(r.second);
}

std::string RawTap::subscribe(const std::string& topic) {
  std::lock_guard lock(impl_->mutex);
  if (auto it = impl_->readers.find(topic); it != impl_->readers.end()) return it->second.first;
  const auto writers = impl_->participant.discovered_writers();
  const auto w = writers.find(topic);
  if (w == writers.end()) return "";
  auto& t = impl_->participant.topic(topic, new RawCdrType(w->second.type));
  dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
  const bool best_effort = w->second.qos.find("best") != std::string::npos;
  q.reliability().kind =
      best_effort ? dds::BEST_EFFORT_RELIABILITY_QOS : dds::RELIABLE_RELIABILITY_QOS;
  q.durability().kind = w->second.qos.find("transient") != std::string::npos
                            ? dds::TRANSIENT_LOCAL_DURABILITY_QOS
                            : dds::VOLATILE_DURABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 64;
  auto& listener = impl_->listeners[topic];
  if (!listener) listener = std::make_unique<Impl::Listener>(impl_->fn, topic);
  auto* reader = impl_->participant.subscriber().create_datareader(
      &t, q, listener.get(), dds::StatusMask::data_available());
  if (!reader) throw std::runtime_error("cannot subscribe to " + topic);
  impl_->readers[topic] = {w->second.type, reader};
  return w->second.type;
}

void RawTap::unsubscribe(const std::string& topic) {
  std::lock_guard lock(impl_->mutex);
  const auto it = impl_->readers.find(topic);
  if (it == impl_->readers.end()) return;
  impl_->participant.subscriber().delete_datareader(it->second.second);
  impl_->readers.erase(it);
}

std::string wait_for_writer(DdsParticipant& participant, const std::string& topic,
                            std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (true) {
    const auto writers = participant.discovered_writers();
    if (auto w = writers.find(topic); w != writers.end()) return w->second.type;
    if (std::chrono::steady_clock::now() > until) return "";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace oscar::inspect
