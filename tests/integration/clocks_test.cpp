// Host clocks (docs/boot.md, "Clocks"): a one-host system whose monitor fakes a clock 250 ms
// ahead (the test hook OSCAR_CLOCK_OFFSET_MS, which the monitor's modules inherit). `oscar ps`
// must report the offset, and boot's merged log must order the host's records by corrected time.
#include <cstdlib>
#include <optional>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "booted_system.hpp"

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::BootedSystem;
using ::testing::HasSubstr;

constexpr const char* kOneSource = R"(
system: skewed
lease: 1s
modules:
  - name: src
    kernels: [ { type: bench_source, name: src, params: { type: Bool } } ]
    mode: { continuous: 20ms }
)";

// Sets the test hook for every process the test starts while it lives.
class ClockShift {
 public:
  explicit ClockShift(const char* ms) { setenv("OSCAR_CLOCK_OFFSET_MS", ms, 1); }
  ~ClockShift() { unsetenv("OSCAR_CLOCK_OFFSET_MS"); }
  ClockShift(const ClockShift&) = delete;
  ClockShift& operator=(const ClockShift&) = delete;
};

std::string ps(int domain, bool json) {
  std::vector<std::string> argv{test::bin("oscar-ps"), "-d", std::to_string(domain)};
  if (json) argv.push_back("--json");
  test::Process p(argv, test::temp_path(json ? "clocks_ps_json.log" : "clocks_ps.log"));
  EXPECT_EQ(p.wait(30s), 0) << p.output();
  return p.output();
}

// The time ("HH:MM:SS.mmm") the merged log prints on the first line containing `text`.
std::string line_time(const std::string& log, const std::string& text) {
  const auto at = log.find(text);
  if (at == std::string::npos) return "";
  const auto begin = log.rfind('\n', at);
  const auto line = log.substr(begin == std::string::npos ? 0 : begin + 1, 12);
  return line.size() == 12 && line[2] == ':' && line[8] == '.' ? line : "";
}

TEST(Clocks, PsReportsAHostsClockOffsetAndTheMergedLogOrdersByCorrectedTime) {
  std::optional<BootedSystem> sys;
  {
    ClockShift shift("250");  // read by the monitor and the modules it starts
    sys.emplace("skewed", kOneSource);
  }
  const auto state = sys->running();
  const auto* src = test::entry(state, "src");
  ASSERT_NE(src, nullptr);
  // The monitor probes every 200 ms at first: an estimate is there within seconds.
  nlohmann::json clock;
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < until) {
    const auto j = nlohmann::json::parse(ps(sys->domain(), /*json=*/true));
    for (const auto& c : j["clocks"]) {
      if (c["host"] == src->host() && c["samples"].get<int>() >= 5) clock = c;
    }
    if (!clock.is_null()) break;
    std::this_thread::sleep_for(500ms);
  }
  ASSERT_FALSE(clock.is_null()) << "no clock estimate of host " << src->host() << " in oscar ps";
  const double offset_ms = clock["offset_ns"].get<double>() / 1e6;
  const double uncertainty_ms = clock["uncertainty_ns"].get<double>() / 1e6;
  // Generous: a loaded or sanitized machine stretches the round trip, not the offset's sign.
  EXPECT_NEAR(offset_ms, 250.0, 25.0) << clock.dump();
  EXPECT_LT(uncertainty_ms, 25.0) << clock.dump();
  const auto table = ps(sys->domain(), /*json=*/false);
  EXPECT_THAT(table, HasSubstr("HOST       CLOCK")) << table;
  EXPECT_THAT(table, ::testing::ContainsRegex(src->host() + " +\\+2[0-9][0-9]\\.[0-9]+ ms ± "))
      << table;
  EXPECT_THAT(table, HasSubstr("! over 10 ms")) << table;

  // The module logged that it started before its state reached the registry, which then said
  // the system runs, which boot noted. The merged log prints each record with its corrected time:
  // with the module's stamps 250 ms ahead and not corrected, its line would read later than
  // boot's. (Times, not line positions: a record that reaches boot later than the printer's hold
  // is printed late, whatever its time.)
  const auto log = sys->boot_output();
  EXPECT_THAT(log, HasSubstr("warning [clocks] host " + src->host() + "'s clock is +2")) << log;
  const auto started = line_time(log, "[src] started");
  const auto running = line_time(log, "[boot] system 'skewed' running");
  ASSERT_FALSE(started.empty()) << log;
  ASSERT_FALSE(running.empty()) << log;
  EXPECT_LT(started, running) << log;
}

}  // namespace
}  // namespace oscar
