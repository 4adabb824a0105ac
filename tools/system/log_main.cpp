// oscar log: the merged log of the running system, time-ordered (by corrected time where a
// host's clock is off), one colour per module.
#include <unistd.h>

#include <csignal>
#include <cstdio>

#include <oscar/configPubSubTypes.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/process_util.hpp"
#include "oscar/registry/clock_topics.hpp"
#include "oscar/registry/log_printer.hpp"
#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/system_options.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

int main(int argc, char** argv) {
  CLI::App app{"oscar log: follows the merged log of the running system until Ctrl-C"};
  oscar::SystemOptions tool;
  double duration_s = 0;
  bool no_colour = false;
  tool.add_to(app);
  app.add_option("--duration", duration_s, "stop after this many seconds");
  app.add_flag("--no-colour", no_colour, "plain text even on a terminal");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  const auto signals = oscar::block_stop_signals();
  try {
    auto participant = tool.participant("oscar-log");
    oscar::LogPrinter printer(stdout, !no_colour && isatty(1) != 0);
    // Records are ordered by their host's corrected time once the printer knows the host
    // (from the system state) and its clock (from its monitor; docs/boot.md, "Clocks").
    oscar::RegistryClient registry(*participant, "log", [&](const oscar::SystemState& s) {
      for (const auto& m : s.modules()) printer.module_host(m.name(), m.host());
    });
    oscar::TopicReader<oscar::HostClock, oscar::HostClockPubSubType> host_clocks(
        *participant, oscar::topics::host_clocks(), [&](const oscar::HostClock& c, const auto&) {
          printer.host_clock(c.host(), std::chrono::nanoseconds(c.offset_ns()),
                             std::chrono::nanoseconds(c.uncertainty_ns()));
        });
    oscar::TopicReader<oscar::LogRecord, oscar::LogRecordPubSubType> logs(
        *participant, oscar::topics::log(),
        [&](const oscar::LogRecord& r, const auto&) { printer.add(r); });
    const auto until = duration_s > 0 ? std::chrono::steady_clock::now() +
                                            std::chrono::milliseconds(long(duration_s * 1000))
                                      : std::chrono::steady_clock::time_point::max();
    while (std::chrono::steady_clock::now() < until &&
           !oscar::wait_for_stop(signals, std::chrono::milliseconds(50))) {
      printer.flush();
    }
    printer.flush(true);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar log: %s\n", e.what());
    return 2;
  }
}
