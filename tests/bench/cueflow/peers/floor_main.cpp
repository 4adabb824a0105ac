// oscar-bench-floor: the floor under every transport of `oscar bench cueflow --all`. The
// publisher stamps the payload, memcpy's it into a shared-memory slot and wakes the subscriber
// with a futex; the subscriber copies the payload out and notes the arrival. No queue, no
// discovery, no serialisation: what two copies and one wake-up cost on this machine. `both` runs
// the two as threads of one process (the multicore row), `pub` and `sub` as two processes.
//   oscar-bench-floor sub --type T --expect N --warmup W --report FILE --domain D
//   oscar-bench-floor pub --type T --count N --period-us P --domain D
#include <fcntl.h>
#include <linux/futex.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <thread>

#include "peer_common.hpp"

namespace {
using namespace oscar::bench;

// The segment: one slot, handed over by bumping `seq` (the futex word). The period (≥ 2 ms) is
// far longer than a copy, so the publisher never overwrites a slot being read.
struct Slot {
  std::atomic<std::uint32_t> seq;
  std::atomic<std::uint32_t> subscriber_ready;
  std::int64_t stamp_ns;
  unsigned char data[1];  // payload_bytes(type) bytes follow
};
static_assert(std::atomic<std::uint32_t>::is_always_lock_free);

long futex(std::atomic<std::uint32_t>* word, int op, std::uint32_t value, const timespec* timeout) {
  return syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(word), op, value, timeout, nullptr, 0);
}

class Segment {
 public:
  Segment(const std::string& name, std::size_t bytes, bool create) : name_(name), size_(bytes) {
    if (create) shm_unlink(name.c_str());  // a segment a killed run left
    int fd = -1;
    for (int attempt = 0; fd < 0 && attempt < 500; ++attempt) {  // the subscriber makes it
      fd = shm_open(name.c_str(), create ? O_CREAT | O_RDWR : O_RDWR, 0600);
      if (fd < 0 && !create) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (fd < 0) throw std::runtime_error("shm_open " + name + ": " + std::strerror(errno));
    if (create && ftruncate(fd, static_cast<off_t>(bytes)) != 0) {
      close(fd);
      throw std::runtime_error("ftruncate: " + std::string(std::strerror(errno)));
    }
    void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    close(fd);
    if (p == MAP_FAILED) throw std::runtime_error("mmap: " + std::string(std::strerror(errno)));
    if (create) std::memset(p, 0, bytes);
    slot_ = static_cast<Slot*>(p);
    owner_ = create;
  }
  ~Segment() {
    munmap(slot_, size_);
    if (owner_) shm_unlink(name_.c_str());
  }
  Slot& slot() { return *slot_; }

 private:
  std::string name_;
  std::size_t size_;
  Slot* slot_ = nullptr;
  bool owner_ = false;
};

void subscribe(Slot& slot, std::size_t bytes, bool in_place, LatencyLog& log) {
  std::vector<unsigned char> copy(bytes);
  std::uint32_t seen = slot.seq.load();
  slot.subscriber_ready = 1;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  const timespec tick{0, 100'000'000};
  while (!log.done() && std::chrono::steady_clock::now() < until) {
    if (slot.seq.load(std::memory_order_acquire) == seen) {
      futex(&slot.seq, FUTEX_WAIT, seen, &tick);
      continue;
    }
    seen = slot.seq.load(std::memory_order_acquire);
    if (!in_place) std::memcpy(copy.data(), slot.data, bytes);
    log.add(steady_ns() - slot.stamp_ns);
  }
}

void publish(Slot& slot, std::size_t bytes, bool in_place, const PeerOptions& o,
             const LatencyLog* log) {
  while (slot.subscriber_ready.load() == 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const std::vector<unsigned char> payload(bytes, 0x80);
  Pacer pacer(o.period_us);
  for (int i = 1; i <= o.count && !(log && log->done()) && !stop_requested(); ++i) {
    auto stamp = steady_ns();  // before the copy: the floor is a copying transport
    std::memcpy(slot.data, payload.data(), bytes);
    if (in_place) stamp = steady_ns();  // the cue written where the subscriber reads it
    slot.stamp_ns = stamp;
    slot.seq.fetch_add(1, std::memory_order_release);
    futex(&slot.seq, FUTEX_WAKE, 1, nullptr);
    pacer.wait();
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar-bench-floor: memcpy + futex floor for oscar bench cueflow"};
  PeerOptions o;
  add_peer_options(app, o);
  bool in_place = false;
  app.add_flag("--in-place", in_place,
               "the zero-copy floor: stamped after the payload is in the slot, read in place");
  CLI11_PARSE(app, argc, argv);
  install_stop_handler();
  try {
    const auto bytes = payload_bytes(o.type);
    Segment segment(fmt::format("/oscar_bench_floor_{}", o.domain), sizeof(Slot) + bytes,
                    o.mode != "pub");
    LatencyLog log(o);
    if (o.mode == "pub") {
      publish(segment.slot(), bytes, in_place, o, nullptr);
      return 0;
    }
    std::thread publisher;
    if (o.mode == "both")
      publisher = std::thread([&] { publish(segment.slot(), bytes, in_place, o, &log); });
    subscribe(segment.slot(), bytes, in_place, log);
    if (publisher.joinable()) publisher.join();
    log.write_report();
    return log.done() ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-bench-floor: %s\n", e.what());
    return 2;
  }
}
