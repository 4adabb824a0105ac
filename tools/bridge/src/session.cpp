#include "session.hpp"

#include <fmt/format.h>
#include <boost/asio/buffer.hpp>
#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/http/read.hpp>
#include <boost/beast/http/write.hpp>
#include <boost/beast/websocket/rfc6455.hpp>

namespace oscar::bridge {
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;

namespace {
constexpr std::size_t kMaxClientMessageBytes = 1 << 20;
constexpr std::size_t kMaxPendingStatuses = 16;  // a stalled client gets the newest

std::string describe(const net::ip::tcp::socket& socket) {
  beast::error_code ec;
  const auto e = socket.remote_endpoint(ec);
  return ec ? std::string("?") : fmt::format("{}:{}", e.address().to_string(), e.port());
}

// True if the comma-separated Sec-WebSocket-Protocol offer names `wanted`.
bool offers(std::string_view offer, std::string_view wanted) {
  while (!offer.empty()) {
    const auto comma = offer.find(',');
    auto item = offer.substr(0, comma);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (item == wanted) return true;
    if (comma == std::string_view::npos) break;
    offer.remove_prefix(comma + 1);
  }
  return false;
}
}  // namespace

Session::Session(net::ip::tcp::socket socket, SessionHost& host, QueueLimits limits,
                 double images_per_second)
    : ws_(std::move(socket)), host_(host), queue_(limits), images_(images_per_second) {
  peer_ = describe(beast::get_lowest_layer(ws_).socket());
}

void Session::start() {
  request_.emplace();
  beast::get_lowest_layer(ws_).expires_after(std::chrono::seconds(30));
  http::async_read(
      beast::get_lowest_layer(ws_), buffer_, *request_,
      [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_request(ec); });
}

void Session::on_request(beast::error_code ec) {
  if (ec) return end();
  if (!websocket::is_upgrade(*request_)) {
    return reject(
        "this is a Foxglove WebSocket server: open it in Foxglove as ws://<address>:<port>");
  }
  const auto offer = (*request_)[http::field::sec_websocket_protocol];
  if (!offers({offer.data(), offer.size()}, kSubprotocol)) {
    return reject(
        fmt::format("this server speaks the WebSocket subprotocol {} only", kSubprotocol));
  }
  beast::get_lowest_layer(ws_).expires_never();
  ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& response) {
    response.set(http::field::sec_websocket_protocol,
                 beast::string_view(kSubprotocol.data(), kSubprotocol.size()));
    response.set(http::field::server, "oscar-bridge");
  }));
  ws_.read_message_max(kMaxClientMessageBytes);
  ws_.async_accept(*request_,
                   [self = shared_from_this()](beast::error_code e) { self->on_accept(e); });
}

void Session::reject(std::string why) {
  rejection_ = std::make_shared<http::response<http::string_body>>(http::status::bad_request,
                                                                   request_->version());
  rejection_->set(http::field::server, "oscar-bridge");
  rejection_->set(http::field::content_type, "text/plain");
  rejection_->keep_alive(false);
  rejection_->body() = std::move(why) + "\n";
  rejection_->prepare_payload();
  http::async_write(beast::get_lowest_layer(ws_), *rejection_,
                    [self = shared_from_this()](beast::error_code, std::size_t) {
                      beast::error_code ignored;
                      beast::get_lowest_layer(self->ws_).socket().shutdown(
                          net::ip::tcp::socket::shutdown_send, ignored);
                      self->end();
                    });
}

void Session::on_accept(beast::error_code ec) {
  if (ec) return end();
  open_ = true;
  request_.reset();
  fmt::print(stderr, "oscar bridge: client {} connected\n", peer_);
  const auto services = host_.services();
  send_text(server_info_json("oscar bridge", host_.session_id(), !services.empty()));
  send_text(advertise_json(host_.channels()));
  if (!services.empty()) send_text(advertise_services_json(services));
  read();
}

void Session::read() {
  ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t bytes) {
    self->on_read(ec, bytes);
  });
}

void Session::on_read(beast::error_code ec, std::size_t) {
  if (ec) return end();
  if (ws_.got_text()) {
    handle(beast::buffers_to_string(buffer_.data()));
  } else {
    handle_binary(beast::buffers_to_string(buffer_.data()));
  }
  buffer_.consume(buffer_.size());
  read();
}

void Session::handle(const std::string& text) {
  try {
    const auto request = parse_client_message(text);
    if (const auto* s = std::get_if<Subscribe>(&request)) {
      for (const auto& [subscription, channel] : s->subscriptions) subscribe(subscription, channel);
    } else if (const auto* u = std::get_if<Unsubscribe>(&request)) {
      for (const auto subscription : u->subscription_ids) unsubscribe(subscription);
    } else {
      set_status(StatusLevel::kError, fmt::format("'{}' is not offered by this server",
                                                  std::get<Unsupported>(request).op));
    }
  } catch (const std::invalid_argument& e) {
    set_status(StatusLevel::kError, e.what());
  }
}

void Session::handle_binary(const std::string& bytes) {
  if (!bytes.empty() && static_cast<std::uint8_t>(bytes[0]) != kServiceCallRequestOpcode) {
    return set_status(StatusLevel::kError,
                      "this server takes no binary messages but service calls (no clientPublish)");
  }
  try {
    auto call =
        parse_service_call({reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()});
    host_.call_service(shared_from_this(), std::move(call));
  } catch (const std::invalid_argument& e) {
    set_status(StatusLevel::kError, e.what());
  }
}

void Session::answer_call(const ServiceCall& call, const std::string& response) {
  queue_call_reply({service_call_response(call.service, call.call, "json", response), true, true});
}

void Session::fail_call(const ServiceCall& call, const std::string& why) {
  queue_call_reply({service_call_failure_json(call.service, call.call, why), false, true});
  set_status(StatusLevel::kError, fmt::format("service call {}: {}", call.call, why));
}

void Session::queue_call_reply(Frame frame) {
  if (pending_call_replies_ >= kMaxPendingCallReplies) return;
  ++pending_call_replies_;
  controls_.push_back(std::move(frame));
  write_next();
}

void Session::subscribe(std::uint32_t subscription, std::uint32_t channel) {
  const auto* c = host_.channel(channel);
  if (!c) {
    return set_status(StatusLevel::kError,
                      fmt::format("subscribe: no channel {} is advertised", channel));
  }
  if (channel_of_.contains(subscription)) {
    return set_status(StatusLevel::kError,
                      fmt::format("subscribe: subscription id {} is in use", subscription));
  }
  if (subscription_of_.contains(channel)) {
    return set_status(
        StatusLevel::kError,
        fmt::format("subscribe: channel {} ({}) is subscribed already", channel, c->topic));
  }
  channel_of_[subscription] = channel;
  subscription_of_[channel] = subscription;
  fmt::print(stderr, "oscar bridge: client {} subscribes to {}\n", peer_, c->topic);
  host_.want(channel);
}

void Session::unsubscribe(std::uint32_t subscription) {
  const auto it = channel_of_.find(subscription);
  if (it == channel_of_.end()) {
    return set_status(StatusLevel::kWarning,
                      fmt::format("unsubscribe: no subscription {}", subscription));
  }
  const auto channel = it->second;
  channel_of_.erase(it);
  subscription_of_.erase(channel);
  queue_.forget(channel);
  images_.forget(channel);
  host_.unwant(channel);
}

void Session::send_text(std::string text) {
  controls_.push_back({std::move(text), false, false});
  write_next();
}

void Session::set_status(StatusLevel level, std::string message) {
  statuses_.push_back(status_json(level, message));
  if (statuses_.size() > kMaxPendingStatuses) statuses_.pop_front();
  write_next();
}

void Session::deliver(const ClientQueue::Message& message) {
  if (!subscription_of_.contains(message.channel)) return;
  if (images_.limits()) {
    const auto* c = host_.channel(message.channel);
    if (c && is_image_schema(c->schema_name) &&
        !images_.admit(message.channel, message.receive_ns)) {
      if (images_.held_back().at(message.channel) == 1) {
        set_status(StatusLevel::kInfo,
                   fmt::format("{}: images come faster than this bridge's image rate for a "
                               "client (--image-rate); the others are held back",
                               c->topic));
      }
      return;
    }
  }
  queue_.push(message);
  write_next();
}

void Session::forget_channel(std::uint32_t channel) {
  const auto it = subscription_of_.find(channel);
  if (it == subscription_of_.end()) return;
  channel_of_.erase(it->second);
  subscription_of_.erase(it);
  queue_.forget(channel);
  images_.forget(channel);
}

std::map<std::uint32_t, std::uint64_t> Session::new_drops() {
  std::map<std::uint32_t, std::uint64_t> fresh;
  for (const auto& [channel, n] : queue_.drops()) {
    if (n > reported_drops_[channel]) fresh[channel] = n - reported_drops_[channel];
    reported_drops_[channel] = n;
  }
  return fresh;
}

void Session::write_next() {
  if (!open_ || writing_ || ended_) return;
  auto done = [self = shared_from_this()](beast::error_code ec, std::size_t) {
    self->on_write(ec);
  };
  if (!controls_.empty() || !statuses_.empty()) {
    bool binary = false;
    if (!controls_.empty()) {
      writing_text_ = std::move(controls_.front().bytes);
      binary = controls_.front().binary;
      if (controls_.front().call_reply) --pending_call_replies_;
      controls_.pop_front();
    } else {
      writing_text_ = std::move(statuses_.front());
      statuses_.pop_front();
    }
    writing_ = true;
    ws_.binary(binary);
    ws_.async_write(net::buffer(writing_text_), std::move(done));
    return;
  }
  while (auto message = queue_.pop()) {
    const auto s = subscription_of_.find(message->channel);
    if (s == subscription_of_.end()) continue;
    writing_header_ = message_data_header(s->second, message->receive_ns);
    writing_payload_ = std::move(message->payload);
    writing_ = true;
    ws_.binary(true);
    const std::array<net::const_buffer, 2> frame{net::buffer(writing_header_),
                                                 net::buffer(*writing_payload_)};
    ws_.async_write(frame, std::move(done));
    return;
  }
}

void Session::on_write(beast::error_code ec) {
  writing_ = false;
  writing_payload_.reset();
  if (ec) return end();
  write_next();
}

void Session::close() {
  beast::error_code ignored;
  beast::get_lowest_layer(ws_).socket().close(ignored);
}

void Session::end() {
  if (ended_) return;
  ended_ = true;
  if (open_) fmt::print(stderr, "oscar bridge: client {} disconnected\n", peer_);
  open_ = false;
  close();  // a write to a stalled client completes now, with an error
  for (const auto& [channel, subscription] : subscription_of_) host_.unwant(channel);
  subscription_of_.clear();
  channel_of_.clear();
  host_.closed(shared_from_this());
}

}  // namespace oscar::bridge
