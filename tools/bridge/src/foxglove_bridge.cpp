#include "foxglove_bridge.hpp"

#include <functional>
#include <optional>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>

#include "channel_directory.hpp"
#include "command_services.hpp"
#include "config_service.hpp"
#include "conversion_worker.hpp"
#include "jpeg_encoder.hpp"
#include "oscar/idl_texts.hpp"
#include "oscar/topics.hpp"
#include "oscar/type_texts.hpp"
#include "raw_tap.hpp"
#include "session.hpp"
#include "side_channels.hpp"
#include "system_graph.hpp"

namespace oscar::bridge {
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;
using Payload = std::shared_ptr<const std::vector<std::uint8_t>>;

namespace {
constexpr std::uint32_t kConfigServiceId = 1;
constexpr std::uint32_t kFirstCommandServiceId = 2;  // kernel command ports, as they appear
// The authority configuration commands from Foxglove carry (as `oscar config --as coordinator`).
constexpr const char* kConfigSender = "coordinator";
}  // namespace

void check_listen_address(const std::string& address) {
  boost::system::error_code ec;
  net::ip::make_address(address, ec);
  if (ec) {
    throw std::invalid_argument(
        fmt::format("--address '{}': expected an IP address such as 127.0.0.1", address));
  }
}

void check_jpeg_quality(int quality) {
  if (quality < kMinJpegQuality || quality > kMaxJpegQuality) {
    throw std::invalid_argument(fmt::format("--jpeg-quality {}: must be {} (smallest) to {} (best)",
                                            quality, kMinJpegQuality, kMaxJpegQuality));
  }
}

// Everything below runs on the one thread that runs io (Fast DDS threads and the conversion and
// configuration workers only post to it).
struct FoxgloveBridge::Impl final : SessionHost {
  // What the bridge knows of a channel it advertised, live or not.
  struct Known {
    std::string topic;
    std::string source;       // the DDS topic read for it (its own topic unless a side channel)
    std::string source_type;  // that topic's IDL type
    std::string schema_name;
    bool side = false;
  };

  BridgeOptions options;
  DdsParticipant& participant;
  std::string started_ns = std::to_string(inspect::now_ns());  // the session id
  net::io_context io{1};
  tcp::acceptor acceptor{io};
  ChannelDirectory directory{[this](const std::string& type) { return announced.idl_text(type); },
                             side_channels_for};
  ConversionSettings conversion{.jpeg_quality = options.jpeg_quality};
  std::set<std::shared_ptr<Session>> sessions;
  void send_to_every_client(const std::string& text) const {
    for (const auto& s : sessions) s->send_text(text);
  }
  std::map<std::uint32_t, int> wanted;   // channel -> subscribers
  std::map<std::string, int> readers;    // DDS topic -> channels wanting it; read while > 0
  std::map<std::uint32_t, Known> known;  // every channel id ever made
  std::map<std::uint32_t, SideChannelActivity> activity;  // live side channels
  std::set<std::string> reported_malformed;
  Payload last_system_state;  // while oscar/system/state is read
  Clock::time_point last_graph_sent{};
  std::unique_ptr<ConfigWorker> config;  // with allow_config
  // With allow_config: the running modules' kernel command ports as services, from the system
  // state (read for them as long as the bridge runs), their requests encoded with these types.
  inspect::IdlTypes request_types;
  std::unique_ptr<CommandServices> commands;
  bool reading_state_for_commands = false;
  // Side channel messages are made on the worker's thread; results come back through `io`.
  ConversionWorker converter{
      [settings = conversion,
       delay = options.test_conversion_delay](const ConversionWorker::Job& job) {
        if (delay.count() > 0) std::this_thread::sleep_for(delay);
        return convert_sample(job.source_type, job.schema_name, *job.cdr, settings);
      },
      [this](ConversionWorker::Result r) {
        net::post(io, [this, r = std::move(r)] { on_converted(r); });
      }};
  Payload state_for_commands;  // the last system state, while it is read for the services
  // The IDL texts of types OSCAR does not define, as their modules announce them. Deleted before
  // `io`, so no Fast DDS thread posts to it once it is gone.
  AnnouncedTypes announced{participant, [this](const std::string& type, const std::string& idl) {
                             net::post(io, [this, type, idl] { on_type_text(type, idl); });
                           }};
  // Last: deleted first, so no Fast DDS thread posts to `io` once it is gone.
  inspect::RawTap tap{
      participant,
      [this](const std::string& topic, std::vector<std::uint8_t> cdr, std::uint64_t receive_ns) {
        auto payload = std::make_shared<const std::vector<std::uint8_t>>(std::move(cdr));
        net::post(io,
                  [this, topic, payload, receive_ns] { on_sample(topic, payload, receive_ns); });
      }};

  Impl(DdsParticipant& p, BridgeOptions o) : options(std::move(o)), participant(p) {
    check_jpeg_quality(options.jpeg_quality);
    listen();
    if (!jpeg_available()) {
      fmt::print(stderr,
                 "oscar bridge: images get no foxglove.CompressedImage side channel: this bridge "
                 "was built without libjpeg (install libjpeg-dev and rebuild)\n");
    }
    if (!options.allow_config) return;
    config = std::make_unique<ConfigWorker>(participant, kConfigSender);
    for (const auto& [type, text] : idl_texts()) request_types.add(text);
    commands = std::make_unique<CommandServices>(request_types, kFirstCommandServiceId);
    if (!net::ip::make_address(options.address).is_loopback()) {
      fmt::print(stderr,
                 "oscar bridge: warning: --allow-config on {}: anyone who reaches port {} there "
                 "may configure this system's modules\n",
                 options.address, acceptor.local_endpoint().port());
    }
  }

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
      auto session =
          std::make_shared<Session>(std::move(s), *this, options.queue, options.image_rate);
      sessions.insert(session);
      session->start();
      accept();
    });
  }

  void deliver(std::uint32_t channel, Payload payload, std::uint64_t receive_ns) {
    const ClientQueue::Message message{channel, std::move(payload), receive_ns};
    for (const auto& s : sessions) s->deliver(message);
  }

  void on_sample(const std::string& topic, const Payload& payload, std::uint64_t receive_ns) {
    if (commands && topic == topics::system_state().name) {
      state_for_commands = payload;
      update_commands(*payload);
    }
    if (const auto raw = directory.id_of(topic); raw && wanted[*raw] > 0) {
      deliver(*raw, payload, receive_ns);
    }
    for (const auto side : directory.sides_of(topic)) convert(side, payload, receive_ns);
  }

  // One sample of `topic` for its side channel `side`, if some client subscribes to it: to the
  // conversion worker, whose result comes back in on_converted().
  void convert(std::uint32_t side, const Payload& payload, std::uint64_t receive_ns) {
    const auto& k = known[side];
    if (k.schema_name == kSystemGraphSchema) {
      last_system_state = payload;
      return send_graph(side, receive_ns);
    }
    if (wanted[side] == 0) return;  // the raw channel alone is read: nothing to convert
    const bool replaced = converter.submit({.channel = side,
                                            .source_type = k.source_type,
                                            .schema_name = k.schema_name,
                                            .cdr = payload,
                                            .receive_ns = receive_ns});
    if (replaced) ++activity[side].skipped;  // a newer sample came before it was converted
  }

  void on_converted(const ConversionWorker::Result& r) {
    const auto a = activity.find(r.channel);
    if (a == activity.end()) return;  // the side channel went meanwhile
    if (!r.error.empty()) {
      ++a->second.skipped;
      if (reported_malformed.insert(a->second.topic).second) {
        fmt::print(stderr, "oscar bridge: {} not converted for {}: {}\n", a->second.source,
                   a->second.topic, r.error);
      }
    } else if (!r.message) {
      ++a->second.skipped;
    } else {
      ++a->second.converted;
      if (wanted[r.channel] > 0) {
        deliver(
            r.channel,
            std::make_shared<const std::vector<std::uint8_t>>(r.message->begin(), r.message->end()),
            r.receive_ns);
      }
    }
  }

  // The system graph from the last system state, to its subscribers.
  void send_graph(std::uint32_t channel, std::uint64_t receive_ns) {
    if (wanted[channel] == 0 || !last_system_state) return;
    try {
      const auto state = system_state_from_cdr(*last_system_state);
      ++activity[channel].converted;
      const auto text = system_graph_json(state, participant.discovered_writers(), side_activity());
      last_graph_sent = Clock::now();
      deliver(channel, std::make_shared<const std::vector<std::uint8_t>>(text.begin(), text.end()),
              receive_ns);
    } catch (const std::runtime_error& e) {
      ++activity[channel].skipped;
      fmt::print(stderr, "oscar bridge: no system graph: {}\n", e.what());
    }
  }

  std::vector<SideChannelActivity> side_activity() {
    std::vector<SideChannelActivity> out;
    for (auto [channel, a] : activity) {
      a.subscribers = wanted[channel];
      out.push_back(a);
    }
    return out;
  }

  void read(const std::string& topic) {
    if (readers[topic]++ > 0) return;
    try {
      if (tap.subscribe(topic).empty()) {
        fmt::print(stderr, "oscar bridge: {} has no writer any more\n", topic);
      }
    } catch (const std::exception& e) {
      fmt::print(stderr, "oscar bridge: cannot read {}: {}\n", topic, e.what());
    }
  }
  void release(const std::string& topic) {
    const auto it = readers.find(topic);
    if (it == readers.end() || it->second == 0) return;
    if (--it->second > 0) return;
    tap.unsubscribe(topic);
    if (topic == topics::system_state().name) last_system_state.reset();
  }

  // A module announced the IDL text of a type of its own: its topics are served from the next
  // discover() on, and its command ports become services.
  void on_type_text(const std::string& type, const std::string& idl) {
    fmt::print(stderr, "oscar bridge: a module announced the IDL text of {}\n", type);
    if (commands) {
      try {
        request_types.add(idl);
        if (state_for_commands) update_commands(*state_for_commands);
      } catch (const std::invalid_argument& e) {
        fmt::print(stderr, "oscar bridge: no command services take {}: its IDL text: {}\n", type,
                   e.what());
      }
    }
    discover();
  }

  void discover() {
    const auto change = directory.update(participant.discovered_writers());
    for (const auto& topic : change.unknown) {
      fmt::print(stderr,
                 "oscar bridge: {} is not served: its type has no IDL text here (it is once its "
                 "module announces one)\n",
                 topic);
    }
    for (const auto channel : change.removed) {
      if (wanted[channel] > 0) release(known[channel].source);
      wanted.erase(channel);
      activity.erase(channel);
      for (const auto& s : sessions) s->forget_channel(channel);
      fmt::print(stderr, "oscar bridge: channel {} {} is gone\n", channel, known[channel].topic);
    }
    for (const auto& c : change.added) {
      const bool side = !c.source.empty();
      const auto source = side ? c.source : c.topic;
      const auto* raw = side ? directory.find(*directory.id_of(c.source)) : &c;
      known[c.id] = {c.topic, source, raw->schema_name, c.schema_name, side};
      if (side) activity[c.id] = {.topic = c.topic, .source = c.source};
      fmt::print(stderr, "oscar bridge: channel {} {} ({}{})\n", c.id, c.topic, c.schema_name,
                 side ? ", from " + c.source : "");
    }
    if (!change.removed.empty()) {
      send_to_every_client(unadvertise_json(change.removed));
    }
    if (!change.added.empty()) {
      send_to_every_client(advertise_json(change.added));
    }
    // The command services follow the system state: read from its first writer on, for good.
    const auto& state_topic = topics::system_state().name;
    if (commands && !reading_state_for_commands && directory.id_of(state_topic)) {
      reading_state_for_commands = true;
      read(state_topic);
    }
  }

  // The running modules' command ports in `state_cdr` (a system state) become the command
  // services: new ones are advertised, those of modules that stopped unadvertised.
  void update_commands(const std::vector<std::uint8_t>& state_cdr) {
    std::vector<KernelCommand> running;
    try {
      running = running_commands(system_state_from_cdr(state_cdr));
    } catch (const std::runtime_error& e) {
      fmt::print(stderr, "oscar bridge: no command services from this system state: {}\n",
                 e.what());
      return;
    }
    const auto change = commands->update(running);
    for (const auto& c : change.unknown_types) {
      fmt::print(stderr,
                 "oscar bridge: {} is not offered: its request type {} has no IDL text here (it "
                 "is once its module announces one)\n",
                 c.service_name(), c.request_type);
    }
    for (const auto id : change.removed) {
      fmt::print(stderr, "oscar bridge: service {} {} is gone\n", id,
                 commands->ever(id)->service_name());
    }
    for (const auto& service : change.added) {
      fmt::print(stderr, "oscar bridge: service {} {} ({})\n", service.id, service.name,
                 service.type);
    }
    if (!change.removed.empty()) {
      send_to_every_client(unadvertise_services_json(change.removed));
    }
    if (!change.added.empty()) {
      send_to_every_client(advertise_services_json(change.added));
    }
  }

  void report() {
    for (const auto& s : sessions) {
      const auto drops = s->new_drops();
      if (drops.empty()) continue;
      std::string what;
      for (const auto& [channel, n] : drops) {
        what += fmt::format("{}{} of {}", what.empty() ? "" : ", ", n, known[channel].topic);
      }
      fmt::print(stderr, "oscar bridge: client {} reads too slowly: dropped the oldest {}\n",
                 s->peer(), what);
      s->set_status(
          StatusLevel::kWarning,
          fmt::format("the bridge dropped the oldest {} (this client read too slowly)", what));
    }
    // The graph's rates and counters move even when the system state does not.
    if (Clock::now() - last_graph_sent < options.report_period) return;
    for (const auto& [channel, k] : known) {
      if (k.schema_name == kSystemGraphSchema && wanted[channel] > 0) {
        send_graph(channel, inspect::now_ns());
      }
    }
  }

  void on_config_done(const std::weak_ptr<Session>& caller, const ServiceCall& call,
                      const std::string& service, const std::string& command,
                      const ConfigWorker::Outcome& outcome) {
    const auto session = caller.lock();
    fmt::print(stderr, "oscar bridge: client {}: {} {}: {}\n", session ? session->peer() : "(gone)",
               service, command, outcome.ok ? "accepted" : outcome.text);
    if (!session) return;
    if (outcome.ok) {
      session->answer_call(call, outcome.text);
    } else {
      session->fail_call(call, command + ": " + outcome.text);
    }
  }

  // SessionHost
  std::vector<ChannelInfo> channels() const override { return directory.channels(); }
  const ChannelInfo* channel(std::uint32_t id) const override { return directory.find(id); }
  void want(std::uint32_t channel) override {
    if (wanted[channel]++ > 0) return;
    const auto& k = known[channel];
    read(k.source);
    if (k.side) {
      fmt::print(stderr, "oscar bridge: converting {} for {} (subscribed)\n", k.source, k.topic);
    }
    if (k.schema_name == kSystemGraphSchema) send_graph(channel, inspect::now_ns());
  }
  void unwant(std::uint32_t channel) override {
    const auto it = wanted.find(channel);
    if (it == wanted.end() || it->second == 0) return;
    if (--it->second > 0) return;
    const auto& k = known[channel];
    release(k.source);
    if (k.side) {
      fmt::print(stderr, "oscar bridge: stopped converting {} for {} after {} messages\n", k.source,
                 k.topic, activity[channel].converted);
    }
  }
  void closed(const std::shared_ptr<Session>& session) override { sessions.erase(session); }
  const std::string& session_id() const override { return started_ns; }
  std::vector<ServiceInfo> services() const override {
    if (!config) return {};
    auto offered = commands->services();
    offered.insert(offered.begin(), config_service_info(kConfigServiceId));
    return offered;
  }
  void call_service(const std::shared_ptr<Session>& caller, ServiceCall call) override {
    if (!config) {
      return caller->fail_call(
          call,
          "this bridge offers no services: it was started without --allow-config, so "
          "Foxglove may not configure modules");
    }
    std::string service = "oscar/config";
    if (call.service != kConfigServiceId) {
      const auto* c = commands->offered(call.service);
      if (!c) {
        if (const auto* gone = commands->ever(call.service)) {
          return caller->fail_call(
              call, fmt::format("service {} ({}) is gone: module '{}' does not run now",
                                call.service, gone->service_name(), gone->module));
        }
        return caller->fail_call(
            call, fmt::format("no service {} is advertised (oscar/config is {}; kernel commands "
                              "are oscar/<module>/<kernel>/<command>)",
                              call.service, kConfigServiceId));
      }
      service = c->service_name();
    }
    if (call.encoding != "json") {
      return caller->fail_call(
          call, fmt::format("encoding '{}' is not offered: {} takes json", call.encoding, service));
    }
    ConfigRequest request;
    try {
      if (call.service == kConfigServiceId) {
        request = parse_config_request(call.payload);
      } else {
        const auto& c = *commands->offered(call.service);
        request = {.module = c.module,
                   .kind = CMD_COMMAND,
                   .args = {c.kernel, c.name},
                   .command = c,
                   .request_cdr = request_cdr(request_types, c.request_type, call.payload)};
      }
    } catch (const std::invalid_argument& e) {
      return caller->fail_call(call,
                               call.service == kConfigServiceId
                                   ? std::string(e.what())
                                   : fmt::format("{}: wrong arguments: {}", service, e.what()));
    }
    const auto command = request.text();
    // A kernel command's service name already says module, kernel and command.
    fmt::print(stderr, "oscar bridge: client {} calls {}\n", caller->peer(),
               call.service == kConfigServiceId ? service + " " + command : service);
    std::weak_ptr<Session> weak = caller;
    const bool queued = config->submit(
        std::move(request), [this, weak, call, service, command](ConfigWorker::Outcome o) {
          net::post(io, [this, weak, call, service, command, o = std::move(o)] {
            on_config_done(weak, call, service, command, o);
          });
        });
    if (!queued) {
      caller->fail_call(call, command + ": refused: too many configuration commands are waiting");
    }
  }
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
        d.report();
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
