#pragma once
// Session: one Foxglove client of the bridge, on the bridge's I/O thread. It completes the
// WebSocket handshake (subprotocol foxglove.websocket.v1), keeps the client's subscriptions,
// hands its service calls to the bridge, and writes one frame at a time: control messages
// (advertise, service call replies, status) first, then messages from its ClientQueue, so a
// client that reads slowly only loses its own oldest messages.

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <boost/beast/websocket/stream.hpp>

#include "client_queue.hpp"
#include "foxglove_protocol.hpp"
#include "image_throttle.hpp"

namespace oscar::bridge {

class Session;

/// What a session needs of the bridge that serves it.
class SessionHost {
 public:
  virtual ~SessionHost() = default;
  virtual std::vector<ChannelInfo> channels() const = 0;
  virtual const ChannelInfo* channel(std::uint32_t id) const = 0;
  /// A client subscribed to / left `channel`: the bridge reads a topic while anyone wants it.
  virtual void want(std::uint32_t channel) = 0;
  virtual void unwant(std::uint32_t channel) = 0;
  /// The session's connection ended (after it released its subscriptions).
  virtual void closed(const std::shared_ptr<Session>& session) = 0;
  virtual const std::string& session_id() const = 0;
  /// The services offered (none unless the bridge was started with --allow-config).
  virtual std::vector<ServiceInfo> services() const = 0;
  /// A client called a service: the bridge answers through caller->answer_call() or
  /// caller->fail_call(), later, on its I/O thread.
  virtual void call_service(const std::shared_ptr<Session>& caller, ServiceCall call) = 0;
};

class Session : public std::enable_shared_from_this<Session> {
 public:
  /// `images_per_second` (> 0) limits each image channel's rate to this client (ImageThrottle).
  Session(boost::asio::ip::tcp::socket socket, SessionHost& host, QueueLimits limits,
          double images_per_second = 0);
  /// Reads the HTTP upgrade request and accepts the WebSocket.
  void start();
  /// Sends a JSON text message (never dropped).
  void send_text(std::string text);
  /// Answers a service call (a Service Call Response, JSON encoded).
  void answer_call(const ServiceCall& call, const std::string& response);
  /// Tells the client its service call failed: serviceCallFailure, and an error status for
  /// viewers that show no call failures.
  void fail_call(const ServiceCall& call, const std::string& why);
  /// Answers waiting at most (of a client that calls but does not read, the newest are lost).
  static constexpr std::size_t kMaxPendingCallReplies = 64;
  /// Queues a message of `channel` if this client subscribes to it (and, for an image, if it
  /// is due at this client's image rate).
  void deliver(const ClientQueue::Message& message);
  /// `channel` is no more: its subscription ends without a word (it was unadvertised).
  void forget_channel(std::uint32_t channel);
  /// Drops since the last call, by channel (reported in the log and to the client).
  std::map<std::uint32_t, std::uint64_t> new_drops();
  /// Tells the client (a status message; of those not sent yet, the newest 16 are kept).
  void set_status(StatusLevel level, std::string message);
  /// Closes the connection.
  void close();
  const std::string& peer() const { return peer_; }

 private:
  void on_request(boost::beast::error_code ec);
  void reject(std::string why);
  void on_accept(boost::beast::error_code ec);
  void read();
  void on_read(boost::beast::error_code ec, std::size_t bytes);
  void handle(const std::string& text);
  void handle_binary(const std::string& bytes);
  void subscribe(std::uint32_t subscription, std::uint32_t channel);
  void unsubscribe(std::uint32_t subscription);
  void write_next();
  void on_write(boost::beast::error_code ec);
  void end();

  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  SessionHost& host_;
  std::string peer_;
  boost::beast::flat_buffer buffer_;
  std::optional<boost::beast::http::request<boost::beast::http::string_body>> request_;
  std::shared_ptr<boost::beast::http::response<boost::beast::http::string_body>> rejection_;
  ClientQueue queue_;
  ImageThrottle images_;
  struct Frame {
    std::string bytes;
    bool binary = false;
    bool call_reply = false;
  };
  void queue_call_reply(Frame frame);

  std::deque<Frame> controls_;  // advertise, call replies, ...
  std::size_t pending_call_replies_ = 0;
  std::deque<std::string> statuses_;                        // not sent yet
  std::map<std::uint32_t, std::uint32_t> channel_of_;       // subscription -> channel
  std::map<std::uint32_t, std::uint32_t> subscription_of_;  // channel -> subscription
  std::map<std::uint32_t, std::uint64_t> reported_drops_;
  bool open_ = false, writing_ = false, ended_ = false;
  // What is being written lives until its write completes.
  std::string writing_text_;
  std::array<std::uint8_t, 13> writing_header_{};
  std::shared_ptr<const std::vector<std::uint8_t>> writing_payload_;
};

}  // namespace oscar::bridge
