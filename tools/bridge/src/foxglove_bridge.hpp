#pragma once
// FoxgloveBridge: serves the running system to Foxglove over the Foxglove WebSocket protocol v1
// (docs/foxglove.md). Every topic with a live writer and a known IDL is a channel (CDR
// messages, OMG IDL schema); a topic is read only while some client subscribes to it, and its
// raw CDR goes to each subscriber as it came, through a bounded per-client queue. Images, poses,
// robot states and the system state have side channels in Foxglove's schemas (JSON), converted
// only while subscribed, on a thread of their own (newest sample wins per side channel); with
// `allow_config`, the service oscar/config configures modules and each running kernel's command
// ports are services oscar/<module>/<kernel>/<command> (command_services.hpp).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "client_queue.hpp"
#include "oscar/dds_participant.hpp"

namespace oscar::bridge {

struct BridgeOptions {
  std::string address = "127.0.0.1";  ///< where to listen: loopback unless told otherwise
  std::uint16_t port = 8765;          ///< 0: any free port (see FoxgloveBridge::port())
  QueueLimits queue;                  ///< per client
  double image_rate = 0;              ///< images per second and channel to a client (0: all)
  int jpeg_quality = 80;              ///< foxglove.CompressedImage side channels, 1..100
  std::chrono::milliseconds discovery_period{200};
  std::chrono::milliseconds report_period{1000};  ///< how often drops are reported
  /// Offer the service oscar/config and the kernels' command ports as services (configuration
  /// commands with the coordinator's authority;
  /// the participant must be allowed to write them, see ToolAuthority::kActAsBoot).
  bool allow_config = false;
  /// Test hook: each side channel conversion takes at least this long more (0: none), to show
  /// that a slow encoder delays no raw channel.
  std::chrono::milliseconds test_conversion_delay{0};
};

/// @throws std::invalid_argument if `address` is no IP address (checked before anything joins
///         the domain).
void check_listen_address(const std::string& address);
/// @throws std::invalid_argument naming --jpeg-quality and its range if `quality` is outside it.
void check_jpeg_quality(int quality);

class FoxgloveBridge {
 public:
  /// Listens on options.address:options.port; serves once run() is called.
  /// @throws std::invalid_argument for an address that is no IP address; std::runtime_error if
  ///         the port cannot be bound (naming it and why).
  FoxgloveBridge(DdsParticipant& participant, BridgeOptions options);
  ~FoxgloveBridge();
  FoxgloveBridge(const FoxgloveBridge&) = delete;
  FoxgloveBridge& operator=(const FoxgloveBridge&) = delete;

  /// The port listened on (the one chosen when options.port was 0).
  std::uint16_t port() const;
  /// Serves clients until `stop` is set, then closes every connection.
  void run(const std::atomic<bool>& stop);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace oscar::bridge
