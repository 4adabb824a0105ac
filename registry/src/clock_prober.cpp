#include "clock_prober.hpp"

#include <charconv>
#include <condition_variable>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include <fmt/format.h>

#include "oscar/time.hpp"

namespace oscar {

std::chrono::nanoseconds test_clock_offset_from_environment() {
  const char* text = std::getenv("OSCAR_CLOCK_OFFSET_MS");
  if (text == nullptr) return {};
  const std::string_view value(text);
  long ms = 0;
  const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), ms);
  if (value.empty() || error != std::errc{} || end != value.data() + value.size()) {
    throw std::invalid_argument(
        fmt::format("OSCAR_CLOCK_OFFSET_MS={}: must be a whole number of milliseconds (a test "
                    "hook that shifts the monitor's clock; unset it outside tests)",
                    value));
  }
  return std::chrono::milliseconds(ms);
}

ClockProber::ClockProber(DdsParticipant& participant, std::string host, long monitor_pid,
                         std::chrono::nanoseconds test_offset)
    : host_(std::move(host)),
      monitor_pid_(monitor_pid),
      test_offset_(test_offset),
      probes_(participant, topics::clock_probe()),
      estimates_(participant, topics::host_clocks()),
      echoes_(participant, topics::clock_echo(),
              [this](const ClockEcho& e, const auto&) { on_echo(e); }),
      prober_([this](std::stop_token stop) {
        using namespace std::chrono_literals;
        const auto start = std::chrono::steady_clock::now();
        auto next = start;
        unsigned long long seq = 0;
        while (!stop.stop_requested()) {
          ClockProbe p;
          p.host(host_);
          p.monitor_pid(static_cast<std::int32_t>(monitor_pid_));
          p.seq(++seq);
          {
            std::lock_guard lock(mutex_);
            // An echo lost (the registry restarting) leaves its seq behind: keep the set small.
            if (in_flight_.size() > ClockEstimator::kWindow) in_flight_.erase(in_flight_.begin());
            in_flight_.insert(seq);
          }
          p.t1_ns(now().count());  // as late as possible before it leaves
          probes_.write(p);
          // More often at first, so that `oscar ps` has a good estimate soon after boot.
          next += next - start < 3s ? 200ms : 1000ms;
          std::mutex wait_mutex;
          std::unique_lock wait_lock(wait_mutex);
          std::condition_variable_any().wait_until(wait_lock, stop, next, [] { return false; });
        }
      }) {}

ClockProber::~ClockProber() {
  prober_.request_stop();
  prober_.join();
}

std::chrono::nanoseconds ClockProber::now() const {
  return std::chrono::nanoseconds(wall_now()) + test_offset_;
}

void ClockProber::on_echo(const ClockEcho& e) {
  const auto t4 = now();  // first, before anything else delays it
  if (e.host() != host_ || e.monitor_pid() != monitor_pid_) return;
  std::lock_guard lock(mutex_);
  if (in_flight_.erase(e.seq()) == 0) return;  // not ours, or answered already
  estimator_.add({.t1 = std::chrono::nanoseconds(e.t1_ns()),
                  .t2 = std::chrono::nanoseconds(e.t2_ns()),
                  .t3 = std::chrono::nanoseconds(e.t3_ns()),
                  .t4 = t4});
  const auto estimate = estimator_.estimate();
  if (!estimate) return;
  HostClock c;
  c.host(host_);
  c.offset_ns(estimate->offset.count());
  c.uncertainty_ns(estimate->uncertainty.count());
  c.samples(static_cast<std::uint32_t>(estimate->samples));
  c.stamp_ns(t4.count());
  estimates_.write(c);
}

}  // namespace oscar
