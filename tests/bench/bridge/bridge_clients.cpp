#include "bridge_clients.hpp"

#include <sys/socket.h>
#include <sys/time.h>

#include <algorithm>
#include <cstring>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

namespace oscar::bench {
namespace {

namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = boost::asio::ip::tcp;

constexpr std::size_t kEncapsulation = 4;  // CDR_LE: 00 01 00 00
constexpr std::size_t kFrameHeader = 13;   // opcode, subscription id (u32), receive time (u64)
constexpr int kReceiveTimeoutS = 5;        // a read that waits longer ends the client

template <class T>
T little_endian(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);  // x86-64 is little-endian, as the bridge writes
  return v;
}

// The ids of the channels advertised for `topics` in an "advertise" message.
std::vector<long> channels_of(const std::string& text, const std::vector<std::string>& topics) {
  std::vector<long> ids;
  const auto j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object() || j.value("op", "") != "advertise") return ids;
  for (const auto& c : j["channels"]) {
    if (std::find(topics.begin(), topics.end(), c.value("topic", "")) != topics.end()) {
      ids.push_back(c["id"].get<long>());
    }
  }
  return ids;
}

}  // namespace

std::uint64_t first_stamp(const std::uint8_t* cdr, std::size_t size) {
  // After the encapsulation: the sequence's length (u32), then its first u64 aligned to 8.
  if (size < kEncapsulation + 16 || cdr[0] != 0 || cdr[1] != 1) return 0;
  const auto* body = cdr + kEncapsulation;
  if (little_endian<std::uint32_t>(body) == 0) return 0;
  return little_endian<std::uint64_t>(body + 8);
}

ClientResult run_client(int port, const std::vector<std::string>& topics,
                        std::chrono::steady_clock::time_point measure_from,
                        const std::atomic<bool>& stop) {
  ClientResult result;
  try {
    boost::asio::io_context io;
    websocket::stream<tcp::socket> ws(io);
    ws.next_layer().connect(
        {boost::asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)});
    const timeval timeout{kReceiveTimeoutS, 0};
    setsockopt(ws.next_layer().native_handle(), SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    ws.set_option(websocket::stream_base::decorator([](websocket::request_type& request) {
      request.set(beast::http::field::sec_websocket_protocol, "foxglove.websocket.v1");
    }));
    ws.handshake("127.0.0.1:" + std::to_string(port), "/");
    std::size_t subscribed = 0;
    beast::flat_buffer buffer;
    while (!stop) {
      buffer.clear();
      ws.read(buffer);
      const auto* data = static_cast<const std::uint8_t*>(buffer.data().data());
      const auto size = buffer.size();
      if (ws.got_text()) {
        for (const auto channel : channels_of(beast::buffers_to_string(buffer.data()), topics)) {
          if (subscribed == topics.size()) break;
          ws.text(true);
          ws.write(boost::asio::buffer(
              nlohmann::json{{"op", "subscribe"},
                             {"subscriptions", {{{"id", ++subscribed}, {"channelId", channel}}}}}
                  .dump()));
        }
        continue;
      }
      const auto now = std::chrono::system_clock::now();
      if (size <= kFrameHeader || data[0] != 0x01) continue;
      if (std::chrono::steady_clock::now() < measure_from) continue;
      ++result.messages;
      const auto stamp = first_stamp(data + kFrameHeader, size - kFrameHeader);
      if (stamp == 0) continue;
      const auto arrival =
          std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
      result.delays_us.push_back(static_cast<double>(arrival - static_cast<long long>(stamp)) /
                                 1e3);
      const auto received = little_endian<std::uint64_t>(data + 5);
      result.after_dds_us.push_back(
          static_cast<double>(arrival - static_cast<long long>(received)) / 1e3);
    }
    ws.close(websocket::close_code::normal);
  } catch (const std::exception& e) {
    if (!stop) result.error = e.what();
  }
  return result;
}

}  // namespace oscar::bench
