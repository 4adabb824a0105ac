#include "foxglove_bridge.hpp"

#include <functional>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>

#include "channel_directory.hpp"
#include "oscar/idl_texts.hpp"
#include "raw_tap.hpp"
#include "session.hpp"

namespace oscar::bridge {
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;

void check_listen_address(const std::string& address) {
  boost::system::error_code ec;
  net::ip::make_address(address, ec);
  if (ec) {
    throw std::invalid_argument(
        fmt::format("--address '{}': expected an IP address such as 127.0.0.1", address));
  }
}

// Everything below runs on the one thread that runs io (Fast DDS threads only post to it).
struct FoxgloveBridge::Impl final : SessionHost {
  BridgeOptions options;
  DdsParticipant& participant;
  std::string started_ns = std::to_string(inspect::now_ns());  // the session id
  net::io_context io{1};
  tcp::acceptor acceptor{io};
  ChannelDirectory directory{idl_texts()};
  std::set<std::shared_ptr<Session>> sessions;
  std::map<std::uint32_t, int> wanted;          // channel -> subscribers; read while > 0
  std::map<std::uint32_t, std::string> topics;  // every channel id ever made -> its topic
  // Last: deleted first, so no Fast DDS thread posts to `io` once it is gone.
  inspect::RawTap tap{
      participant,
      [this](const std::string& topic, std::vector<std::uint8_t> cdr, std::uint64_t receive_ns) {
        auto payload = std::make_shared<const std::vector<std::uint8_t>>(std::move(cdr));
        net::post(io,
                  [this, topic, payload, receive_ns] { on_sample(topic, payload, receive_ns); });
      }};

  Impl(DdsParticipant& p, BridgeOptions o) : options(std::move(o)), participant(p) { listen(); }

  void listen() {
    check_listen_address(options.address);
    boost::system::error_code ec;
    const tcp::endpoint endpoint(net::ip::make_address(options.address), options.port);
    acceptor.open(endpoint.protocol(), ec);
    if (!ec) acceptor.set_option(net::socket_base::reuse_address(true), ec);
    if (!ec) acceptor.bind(endpoint, ec);
    if (!ec) acceptor.listen(net::socket_base::max_listen_connections, ec);
    if (ec) {
      throw std::runtime_error(
          fmt::format("cannot listen on {}:{}: {}", options.address, options.port, ec.message()));
    }
  }

  void accept() {
    acceptor.async_accept([this](boost::system::error_code ec, tcp::socket s) {
      if (ec) return;  // the acceptor was closed
      // Each message goes out whole at once: with Nagle's algorithm the tail of a frame waited
      // for the client's delayed ACK (a GvImage to 4 clients took a frame period, 33 ms, p50).
      boost::system::error_code ignored;
      s.set_option(tcp::no_delay(true), ignored);
      auto session = std::make_shared<Session>(std::move(s), *this, options.queue);
      sessions.insert(session);
      session->start();
      accept();
    });
  }

  void on_sample(const std::string& topic,
                 const std::shared_ptr<const std::vector<std::uint8_t>>& payload,
                 std::uint64_t receive_ns) {
    const auto channel = directory.id_of(topic);
    if (!channel || wanted[*channel] == 0) return;  // unsubscribed meanwhile
    const ClientQueue::Message message{*channel, payload, receive_ns};
    for (const auto& s : sessions) s->deliver(message);
  }

  void discover() {
    const auto change = directory.update(participant.discovered_writers());
    for (const auto& topic : change.unknown) {
      fmt::print(stderr, "oscar bridge: {} is not served: its type has no IDL text here\n", topic);
    }
    for (const auto channel : change.removed) {
      if (wanted[channel] > 0) tap.unsubscribe(topic_of_removed(channel));
      wanted.erase(channel);
      for (const auto& s : sessions) s->forget_channel(channel);
    }
    for (const auto& c : change.added) {
      fmt::print(stderr, "oscar bridge: channel {} {} ({})\n", c.id, c.topic, c.schema_name);
      topics[c.id] = c.topic;
    }
    if (!change.removed.empty()) {
      for (const auto channel : change.removed) {
        fmt::print(stderr, "oscar bridge: channel {} {} is gone\n", channel, topics[channel]);
      }
      const auto text = unadvertise_json(change.removed);
      for (const auto& s : sessions) s->send_text(text);
    }
    if (!change.added.empty()) {
      const auto text = advertise_json(change.added);
      for (const auto& s : sessions) s->send_text(text);
    }
  }
  std::string topic_of_removed(std::uint32_t channel) { return topics[channel]; }

  void report_drops() {
    for (const auto& s : sessions) {
      const auto drops = s->new_drops();
      if (drops.empty()) continue;
      std::string what;
      for (const auto& [channel, n] : drops) {
        what += fmt::format("{}{} of {}", what.empty() ? "" : ", ", n, topics[channel]);
      }
      fmt::print(stderr, "oscar bridge: client {} reads too slowly: dropped the oldest {}\n",
                 s->peer(), what);
      s->set_status(
          StatusLevel::kWarning,
          fmt::format("the bridge dropped the oldest {} (this client read too slowly)", what));
    }
  }

  // SessionHost
  std::vector<ChannelInfo> channels() const override { return directory.channels(); }
  const ChannelInfo* channel(std::uint32_t id) const override { return directory.find(id); }
  void want(std::uint32_t channel) override {
    if (wanted[channel]++ > 0) return;
    const auto& topic = topics[channel];
    try {
      if (tap.subscribe(topic).empty()) {
        fmt::print(stderr, "oscar bridge: {} has no writer any more\n", topic);
      }
    } catch (const std::exception& e) {
      fmt::print(stderr, "oscar bridge: cannot read {}: {}\n", topic, e.what());
    }
  }
  void unwant(std::uint32_t channel) override {
    const auto it = wanted.find(channel);
    if (it == wanted.end() || it->second == 0) return;
    if (--it->second == 0) tap.unsubscribe(topics[channel]);
  }
  void closed(const std::shared_ptr<Session>& session) override { sessions.erase(session); }
  const std::string& session_id() const override { return started_ns; }
};

FoxgloveBridge::FoxgloveBridge(DdsParticipant& participant, BridgeOptions options)
    : impl_(std::make_unique<Impl>(participant, std::move(options))) {}

FoxgloveBridge::~FoxgloveBridge() = default;

std::uint16_t FoxgloveBridge::port() const { return impl_->acceptor.local_endpoint().port(); }

void FoxgloveBridge::run(const std::atomic<bool>& stop) {
  auto& d = *impl_;
  d.accept();
  net::steady_timer tick(d.io);
  auto last_discovery = Clock::now() - d.options.discovery_period;
  auto last_report = Clock::now();
  std::optional<Clock::time_point> closing_since;
  std::function<void()> on_tick = [&] {
    const auto now = Clock::now();
    if (stop && !closing_since) {
      closing_since = now;
      boost::system::error_code ignored;
      d.acceptor.close(ignored);
      for (const auto& s : std::set(d.sessions)) s->close();
    }
    if (closing_since) {
      // Each session ends once its pending read and write have completed with an error.
      if (d.sessions.empty() || now - *closing_since > std::chrono::seconds(2)) return d.io.stop();
    } else {
      if (now - last_discovery >= d.options.discovery_period) {
        d.discover();
        last_discovery = now;
      }
      if (now - last_report >= d.options.report_period) {
        d.report_drops();
        last_report = now;
      }
    }
    tick.expires_after(std::chrono::milliseconds(50));
    tick.async_wait([&](boost::system::error_code) { on_tick(); });
  };
  on_tick();
  d.io.run();
}

}  // namespace oscar::bridge
