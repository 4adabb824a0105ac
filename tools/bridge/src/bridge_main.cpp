// oscar bridge foxglove: serves the running system to Foxglove (docs/foxglove.md).
#include <atomic>
#include <csignal>
#include <cstdio>

#include <fmt/format.h>

#include <oscar/command_line.hpp>
#include "foxglove_bridge.hpp"
#include "oscar/registry/system_options.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bridge: serve the running system to a viewer"};
  app.require_subcommand(1);
  auto* foxglove = app.add_subcommand(
      "foxglove",
      "a Foxglove WebSocket server (protocol v1): every topic as a channel with its OMG IDL "
      "schema and raw CDR messages; images (raw and JPEG), poses, robot states and the system "
      "graph also in "
      "Foxglove's schemas (JSON)");
  oscar::SystemOptions tool;
  tool.add_to(*foxglove);
  oscar::bridge::BridgeOptions options;
  foxglove->add_option("--address", options.address, "address to listen on")->capture_default_str();
  foxglove->add_option("--port", options.port, "TCP port to listen on (0: any free port)")
      ->capture_default_str();
  foxglove
      ->add_option("--queue-messages", options.queue.messages_per_channel,
                   "per client and channel: messages queued before the oldest is dropped")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 20));
  std::size_t queue_mib = options.queue.bytes >> 20;
  foxglove
      ->add_option("--queue-mib", queue_mib,
                   "per client: MiB of messages queued before the oldest are dropped")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 20));
  foxglove
      ->add_option("--image-rate", options.image_rate,
                   "per client and image channel: images per second at most (0: every image)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  foxglove
      ->add_option("--jpeg-quality", options.jpeg_quality,
                   "JPEG quality of the foxglove.CompressedImage side channels, 1 (smallest) to "
                   "100 (best)")
      ->capture_default_str();
  foxglove->add_flag(
      "--allow-config", options.allow_config,
      "offer the service oscar/config: Foxglove users may then configure modules with the "
      "coordinator's authority (with a keystore, as the identity operator_boot)");
  int conversion_delay_ms = 0;  // a test hook (tests/foxglove), hidden from --help
  foxglove->add_option("--test-conversion-delay-ms", conversion_delay_ms)
      ->group("")
      ->check(CLI::Range(0, 10000));
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  options.test_conversion_delay = std::chrono::milliseconds(conversion_delay_ms);
  options.queue.bytes = queue_mib << 20;
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    oscar::bridge::check_listen_address(options.address);
    oscar::bridge::check_jpeg_quality(options.jpeg_quality);
    // Only with --allow-config does the bridge act: otherwise it takes the identity that may
    // only look (docs/security.md).
    auto participant =
        tool.participant("oscar-bridge", options.allow_config ? oscar::ToolAuthority::kActAsBoot
                                                              : oscar::ToolAuthority::kLook);
    oscar::bridge::FoxgloveBridge bridge(*participant, options);
    fmt::print(
        stderr, "oscar bridge: serving domain {} to Foxglove at ws://{}:{}{}\n",
        participant->domain(), options.address, bridge.port(),
        options.allow_config ? " (service oscar/config: clients may configure modules)" : "");
    bridge.run(g_stop);
    fmt::print(stderr, "oscar bridge: stopped\n");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar bridge: %s\n", e.what());
    return 1;
  }
}
