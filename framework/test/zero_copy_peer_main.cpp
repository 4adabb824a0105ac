// oscar-zero-copy-peer: one end of a zero-copy channel for tests/zero_copy_test.cpp. Prints a
// line per cue with the chunk's identity (segment, offset, sequence number), so the test can
// show that the consumer read the producer's chunk and not a copy, and the consumer the latency
// from publish to take (the producer's steady-clock stamp in header.stamps[0]).
//   oscar-zero-copy-peer pub TYPE TOPIC COUNT PERIOD_MS HOLD_LOANS LINGER(0|1) FIRST_SEQ
//   oscar-zero-copy-peer sub TYPE TOPIC EXPECT(0 = forever) HOLD
//   oscar-zero-copy-peer ring TYPE TOPIC EXPECT DEPTH  (a sub keeping cues in oscar::RingBuffer)
//   oscar-zero-copy-peer config COUNT    (RouDi's configuration: COUNT chunks per plain type)
// TYPE: PlainBool, PlainLineSeg3DSeq or PlainGvImage. A publisher holds HOLD_LOANS chunks unused
// (to show they come back when it is killed) and with LINGER stays after its last cue; a
// subscriber keeps its HOLD newest cues, as an input's ring buffer does. With
// OSCAR_PEER_PORTS_AFTER=FILE in its environment, the peer prints "joined" once it joined RouDi and
// asks for its ports once FILE exists.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "oscar/ring_buffer.hpp"
#include "zero_copy/chunk_identity.hpp"
#include "zero_copy/chunk_publisher.hpp"
#include "zero_copy/chunk_subscriber.hpp"
#include "zero_copy/mempools.hpp"
#include "zero_copy/roudi.hpp"

namespace {
using namespace oscar::zero_copy;

// What the producer writes into cue `seq`, and what the consumer checks.
void fill(oscar::PlainBool& cue, std::uint64_t seq) { cue.value(seq % 2 == 1); }
bool check(const oscar::PlainBool& cue, std::uint64_t seq) { return cue.value() == (seq % 2 == 1); }
void fill(oscar::PlainLineSeg3DSeq& cue, std::uint64_t seq) {
  cue.line_count(100);
  cue.lines()[99].ex(static_cast<double>(seq));
}
bool check(const oscar::PlainLineSeg3DSeq& cue, std::uint64_t seq) {
  return cue.line_count() == 100 && cue.lines()[99].ex() == static_cast<double>(seq);
}
void fill(oscar::PlainGvImage& cue, std::uint64_t seq) {
  cue.dx(768);
  cue.dy(576);
  cue.byte_count(768 * 576);
  cue.image()[0] = static_cast<std::uint8_t>(seq);
  cue.image()[768 * 576 - 1] = static_cast<std::uint8_t>(seq * 7);
}
bool check(const oscar::PlainGvImage& cue, std::uint64_t seq) {
  return cue.byte_count() == 768 * 576 && cue.image()[0] == static_cast<std::uint8_t>(seq) &&
         cue.image()[768 * 576 - 1] == static_cast<std::uint8_t>(seq * 7);
}

std::uint64_t steady_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::steady_clock::now().time_since_epoch())
                                        .count());
}

void print(const char* what, std::uint64_t seq, const void* payload, bool ok,
           std::uint64_t latency_ns = 0) {
  const auto id = identify_chunk(payload);
  std::printf("%s seq=%llu segment=%lld offset=%llu chunk=%llu ok=%d latency_us=%.1f\n", what,
              static_cast<unsigned long long>(seq), id ? static_cast<long long>(id->segment) : -1,
              id ? static_cast<unsigned long long>(id->offset) : 0ULL,
              id ? static_cast<unsigned long long>(id->sequence) : 0ULL, ok ? 1 : 0,
              static_cast<double>(latency_ns) / 1000.0);
  std::fflush(stdout);
}

template <class T>
int publish(const std::string& topic, long count, long period_ms, long hold_loans, bool linger,
            long first_seq) {
  PlainPublisher<T> publisher(topic);
  std::vector<typename PlainPublisher<T>::Loan> held;
  for (long i = 0; i < hold_loans; ++i) {
    held.push_back(publisher.loan());
    if (!held.back()) {
      std::printf("loan failed while holding %ld\n", i);
      return 3;
    }
  }
  std::printf("holding %ld loans\n", hold_loans);
  std::fflush(stdout);
  for (int waited = 0; count > 0 && !publisher.has_subscribers(); ++waited) {
    if (waited > 6000) return 4;  // 60 s without a subscriber
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  for (long i = 0; i < count; ++i) {
    const auto seq = static_cast<std::uint64_t>(first_seq + i);
    auto cue = publisher.loan();
    if (!cue) {
      std::printf("loan failed at seq=%llu\n", static_cast<unsigned long long>(seq));
      return 3;
    }
    cue->header().seq(seq);
    fill(*cue, seq);
    print("published", seq, cue.get(), true);
    // The latency a consumer prints runs from here (steady clock: same host).
    cue->header().stamps()[0] = steady_ns();
    cue->header().stamp_count(1);
    publisher.publish(std::move(cue));
    std::this_thread::sleep_for(std::chrono::milliseconds(period_ms));
  }
  std::printf("done\n");
  std::fflush(stdout);
  while (linger) std::this_thread::sleep_for(std::chrono::seconds(1));
  return 0;
}

template <class T>
int subscribe(const std::string& topic, long expect, long hold) {
  PlainSubscriber<T> subscriber(topic);
  std::deque<std::shared_ptr<const T>> ring;  // the newest `hold` cues, as a ring buffer keeps
  std::printf("subscribed\n");
  std::fflush(stdout);
  for (long received = 0; expect == 0 || received < expect;) {
    auto cue = subscriber.take(std::chrono::seconds(1));
    if (!cue) continue;
    const auto latency_ns = steady_ns() - cue->header().stamps()[0];
    const auto seq = cue->header().seq();
    print("received", seq, cue.get(), check(*cue, seq), latency_ns);
    ring.push_back(std::move(cue));
    if (static_cast<long>(ring.size()) > hold) ring.pop_front();
    ++received;
  }
  return 0;
}

// Cues kept in the framework's RingBuffer (as an input keeps them): each entry is the chunk
// itself; an evicted cue's chunk goes back to RouDi, and held cues stay readable after the
// subscriber object is gone.
template <class T>
int keep_in_ring(const std::string& topic, long expect, long depth) {
  oscar::RingBuffer ring(static_cast<std::size_t>(depth));
  {
    PlainSubscriber<T> subscriber(topic);
    std::printf("subscribed\n");
    std::fflush(stdout);
    for (long received = 0; received < expect;) {
      auto cue = subscriber.take(std::chrono::seconds(1));
      if (!cue) continue;
      const auto seq = cue->header().seq();
      const void* where = cue.get();
      ring.push(cue, static_cast<oscar::Stamp>(cue->header().stamps()[0]), 0);
      const auto latest = ring.latest();
      print("ringed", seq, latest->cue.get(), latest->cue.get() == where && check(*cue, seq));
      ++received;
    }
  }  // the subscriber object ends here; the ring still holds its newest chunks
  bool readable = true;
  for (const auto& entry : ring.latest(ring.depth())) {
    const auto& cue = *std::static_pointer_cast<const T>(entry.cue);
    readable = readable && check(cue, cue.header().seq());
  }
  std::printf("after the subscriber: %zu cues held, readable=%d\n",
              ring.latest(ring.depth()).size(), readable ? 1 : 0);
  ring.clear();
  std::printf("released\n");
  std::fflush(stdout);
  return readable ? 0 : 1;
}

template <class T>
int run(const std::vector<std::string>& a) {
  if (a[1] == "pub" && a.size() == 9)
    return publish<T>(a[3], std::stol(a[4]), std::stol(a[5]), std::stol(a[6]), a[7] == "1",
                      std::stol(a[8]));
  if (a[1] == "sub" && a.size() == 6) return subscribe<T>(a[3], std::stol(a[4]), std::stol(a[5]));
  if (a[1] == "ring" && a.size() == 6)
    return keep_in_ring<T>(a[3], std::stol(a[4]), std::stol(a[5]));
  std::fprintf(stderr, "usage: see the head of zero_copy_peer_main.cpp\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> a(argv, argv + argc);
  if (a.size() == 3 && a[1] == "config") {
    std::printf(
        "%s",
        roudi_config(plain_cue_mempools(static_cast<std::uint32_t>(std::stoul(a[2])))).c_str());
    return 0;
  }
  if (a.size() < 4) return run<oscar::PlainBool>({"", ""});
  try {
    if (const auto why_not = join_roudi("oscar-zc-" + a[1] + "-" + std::to_string(getpid()))) {
      std::printf("no zero-copy: %s\n", why_not->c_str());
      return 5;
    }
    if (const char* go = std::getenv("OSCAR_PEER_PORTS_AFTER")) {
      std::printf("joined\n");
      std::fflush(stdout);
      while (!std::filesystem::exists(go))
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (a[2] == "PlainBool") return run<oscar::PlainBool>(a);
    if (a[2] == "PlainLineSeg3DSeq") return run<oscar::PlainLineSeg3DSeq>(a);
    if (a[2] == "PlainGvImage") return run<oscar::PlainGvImage>(a);
    std::fprintf(stderr, "unknown type %s\n", a[2].c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-zero-copy-peer: %s\n", e.what());
    return 1;
  }
}
