// oscar-bench-iceoryx: iceoryx 2.0 zero-copy for `oscar bench cueflow --all`. The publisher
// loans a chunk from RouDi's shared memory, fills the payload, stamps it and publishes; the
// subscriber waits on a wait set, takes the chunk (no copy), notes the arrival and releases it.
// Needs a running RouDi (`iox-roudi`, started by the bench). `both` runs both in one process.
//   oscar-bench-iceoryx sub --type T --expect N --warmup W --report FILE
//   oscar-bench-iceoryx pub --type T --count N --period-us P
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <thread>

#include <iceoryx_posh/popo/untyped_publisher.hpp>
#include <iceoryx_posh/popo/untyped_subscriber.hpp>
#include <iceoryx_posh/popo/wait_set.hpp>
#include <iceoryx_posh/runtime/posh_runtime.hpp>

#include "peer_common.hpp"

namespace {
using namespace oscar::bench;

struct CueHead {
  std::int64_t stamp_ns;
  std::uint64_t seq;
};  // the payload's bytes follow

iox::capro::ServiceDescription service(const PeerOptions& o) {
  return {"oscar_bench", iox::capro::IdString_t(iox::cxx::TruncateToCapacity, o.type.c_str()),
          "cue"};
}

void subscribe(const PeerOptions& o, LatencyLog& log) {
  iox::popo::SubscriberOptions options;
  options.queueCapacity = 16;  // as the DDS readers' keep-last 16
  iox::popo::UntypedSubscriber subscriber(service(o), options);
  iox::popo::WaitSet<> waitset;
  waitset.attachState(subscriber, iox::popo::SubscriberState::HAS_DATA).or_else([](auto) {
    throw std::runtime_error("cannot attach the subscriber to a wait set");
  });
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!log.done() && std::chrono::steady_clock::now() < until) {
    waitset.timedWait(iox::units::Duration::fromMilliseconds(100));
    for (;;) {
      const auto taken = subscriber.take();
      if (taken.has_error()) break;
      const void* chunk = taken.value();
      log.add(steady_ns() - static_cast<const CueHead*>(chunk)->stamp_ns);
      subscriber.release(chunk);
    }
  }
}

void publish(const PeerOptions& o, const LatencyLog* log) {
  iox::popo::UntypedPublisher publisher(service(o));
  while (!publisher.hasSubscribers()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // as the DDS programs
  const auto bytes = payload_bytes(o.type);
  const std::vector<unsigned char> payload(bytes, 0x80);
  Pacer pacer(o.period_us);
  for (int i = 1; i <= o.count && !(log && log->done()) && !stop_requested(); ++i) {
    auto loaned =
        publisher.loan(static_cast<std::uint32_t>(sizeof(CueHead) + bytes), alignof(CueHead));
    if (loaned.has_error()) throw std::runtime_error("no chunk to loan (RouDi's mempools)");
    auto* head = static_cast<CueHead*>(loaned.value());
    std::memcpy(head + 1, payload.data(), bytes);  // the producer writes its cue in place
    head->seq = static_cast<std::uint64_t>(i);
    head->stamp_ns = steady_ns();
    publisher.publish(loaned.value());
    pacer.wait();
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar-bench-iceoryx: iceoryx 2.0 zero-copy peer of oscar bench cueflow"};
  PeerOptions o;
  add_peer_options(app, o);
  CLI11_PARSE(app, argc, argv);
  install_stop_handler();
  try {
    const auto name = fmt::format("oscar-bench-iox-{}-{}", o.mode, getpid());
    iox::runtime::PoshRuntime::initRuntime(
        iox::RuntimeName_t(iox::cxx::TruncateToCapacity, name.c_str()));
    LatencyLog log(o);
    if (o.mode == "pub") {
      publish(o, nullptr);
      return 0;
    }
    std::thread publisher;
    if (o.mode == "both") publisher = std::thread([&] { publish(o, &log); });
    subscribe(o, log);
    if (publisher.joinable()) publisher.join();
    log.write_report();
    return log.done() ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-bench-iceoryx: %s\n", e.what());
    return 2;
  }
}
