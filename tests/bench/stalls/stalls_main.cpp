// oscar bench stalls: how long this machine holds a running thread back, the floor under every
// timing figure measured on it (docs/benchmarks.md). A thread per CPU, pinned to it, reads the
// clock in a loop; every gap between two readings is time it did not run. The kernel's own
// accounting (/proc/thread-self/schedstat) tells how much of that the thread waited behind other
// tasks of this system; the rest went to interrupts or, on a virtual machine, to the host running
// something else on that CPU.
//   oscar bench stalls [--seconds S]
// Normal scheduling on purpose: a SCHED_FIFO spinner on every CPU is throttled by the kernel for
// 50 ms a second (sched_rt_runtime_us), which would be counted as stalls.
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

namespace {
using Clock = std::chrono::steady_clock;
using std::chrono::nanoseconds;

constexpr std::array<nanoseconds, 4> kBounds{
    std::chrono::microseconds(100), std::chrono::microseconds(500), std::chrono::milliseconds(1),
    std::chrono::milliseconds(5)};

struct Stalls {
  int cpu = 0;
  std::array<long, kBounds.size()> longer_than{};  ///< gaps longer than each of kBounds
  nanoseconds longest{0}, lost{0};                 ///< lost: the sum of gaps over 100 us
  nanoseconds queued{0};  ///< waiting behind other tasks of this system (schedstat)
};

// Spins on `cpu` until `end`, counting the gaps in its clock readings.
Stalls watch(int cpu, Clock::time_point end) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (pthread_setaffinity_np(pthread_self(), sizeof set, &set) != 0) {
    throw std::runtime_error(fmt::format("cannot pin a thread to CPU {}", cpu));
  }
  const auto queued_ns = [] {
    std::ifstream in("/proc/thread-self/schedstat");
    long long on_cpu = 0, waiting = 0;
    in >> on_cpu >> waiting;
    return nanoseconds(waiting);
  };
  Stalls s;
  s.cpu = cpu;
  const auto queued_before = queued_ns();
  for (auto last = Clock::now(), now = last; now < end; last = now) {
    now = Clock::now();
    const auto gap = now - last;
    if (gap <= kBounds.front()) continue;
    s.lost += gap;
    s.longest = std::max(s.longest, nanoseconds(gap));
    for (std::size_t i = 0; i < kBounds.size(); ++i) s.longer_than[i] += gap > kBounds[i] ? 1 : 0;
  }
  s.queued = queued_ns() - queued_before;
  return s;
}

double ms(nanoseconds d) { return std::chrono::duration<double, std::milli>(d).count(); }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench stalls: how long this machine holds a running thread back"};
  double seconds = 10;
  app.add_option("--seconds", seconds, "how long to watch")->check(CLI::PositiveNumber);
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    cpu_set_t allowed;
    if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) {
      throw std::runtime_error("cannot read which CPUs this process may use");
    }
    std::vector<int> cpus;
    for (int c = 0; c < CPU_SETSIZE; ++c) {
      if (CPU_ISSET(c, &allowed)) cpus.push_back(c);
    }
    const auto end = Clock::now() + std::chrono::duration_cast<nanoseconds>(
                                        std::chrono::duration<double>(seconds));
    std::vector<Stalls> stalls(cpus.size());
    std::vector<std::thread> threads;
    for (std::size_t i = 0; i < cpus.size(); ++i) {
      threads.emplace_back([&, i] { stalls[i] = watch(cpus[i], end); });
    }
    for (auto& t : threads) t.join();
    fmt::print(
        "oscar bench stalls: a spinning thread per CPU for {:g} s; gaps in its clock readings\n"
        "{:<4} {:>8} {:>8} {:>8} {:>8} | {:>11} {:>9} | {:>16}\n",
        seconds, "cpu", ">0.1 ms", ">0.5 ms", ">1 ms", ">5 ms", "longest ms", "lost ms",
        "behind tasks ms");
    for (const auto& s : stalls) {
      fmt::print("{:<4} {:>8} {:>8} {:>8} {:>8} | {:>11.2f} {:>9.1f} | {:>16.1f}\n", s.cpu,
                 s.longer_than[0], s.longer_than[1], s.longer_than[2], s.longer_than[3],
                 ms(s.longest), ms(s.lost), ms(s.queued));
    }
    fmt::print(
        "lost: the gaps over 0.1 ms added up; behind tasks: of the whole run, the time the "
        "kernel kept the thread\nwaiting for other tasks of this system. Lost time beyond that "
        "went to interrupts or to the host of a virtual machine.\n");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar bench stalls: %s\n", e.what());
    return 1;
  }
}
