// oscar bench discovery: what Fast DDS's simple discovery alone costs N participants on this
// host, without OSCAR. N processes, each with one bare Fast DDS participant configured as
// OSCAR's are (UDP on loopback, unicast discovery to the participant ids started before it,
// lease 3 s announced every second) and E writers of topics nobody reads (a module announces
// about six endpoints), started all at once or, with --at-a-time K, as boot starts a host's
// modules (the next while fewer than K are still finding those before them). It reports how
// long until every participant has discovered every other one, the CPU the processes used until
// then, and the CPU they use per second afterwards, when nothing happens but discovery's upkeep.
// The figures sit beside `oscar bench boot`'s: the part of a boot that is Fast DDS's and grows
// faster than the square of the participants.
//
// With --rejoins K it then kills the newest participant K times (kill -9), waits until the
// others have dropped it (its lease) and starts it again, and reports how long the new one took
// to find every other one: what a restarted module's participant needs, without OSCAR, beside
// `oscar bench restart`'s figures. With --security every participant authenticates with a
// keystore made here (`oscar security init`), as a module of a system does, and "found" means
// authenticated.
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "bench_system.hpp"  // tests/common: make_bench_keystore()
#include "oscar/raw_cdr_type.hpp"
#include "oscar/security_files.hpp"
#include "percentile.hpp"   // tests/common
#include "process.hpp"      // tests/common: test_domain()
#include "process_cpu.hpp"  // tests/common

namespace {
namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;
using Clock = std::chrono::steady_clock;

struct Options {
  int participants = 20;
  int endpoints = 6;
  int upkeep_s = 5;
  int timeout_s = 120;
  int initial_announcements = 5;  // Fast DDS's default
  int at_a_time = 0;              // 0: all at once
  int rejoins = 0;
  bool shared_memory = false;
  bool security = false;
  bool json = false;
  std::string keystore;  // with --security: made here, one identity per participant
};

// Fast DDS drops a participant whose announcements stopped after this lease (OSCAR's); a
// killed one is started again only after it, so that every rejoin is one the others do not know.
constexpr int kLeaseSeconds = 3;

// The same port arithmetic as OSCAR's (RTPS's well-known ports, d1 = 10, d3 = 11).
std::uint32_t metatraffic_port(int domain, int id) {
  return static_cast<std::uint32_t>(7400 + 250 * domain + 10 + 2 * id);
}

Locator_t loopback(std::uint32_t port) {
  Locator_t l;
  IPLocator::setIPv4(l, "127.0.0.1");
  l.port = port;
  return l;
}

// Counts the participants found: discovered, or with security authenticated (Fast DDS reports
// a secured participant discovered before its handshake, and matches nothing of it until then).
class CountingListener final : public dds::DomainParticipantListener {
 public:
  explicit CountingListener(bool secured) : secured_(secured) {}
  void on_participant_discovery(
      dds::DomainParticipant*, eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERY_STATUS;
    if (info.status == Status::DISCOVERED_PARTICIPANT && !secured_) ++found;
    if (info.status == Status::REMOVED_PARTICIPANT || info.status == Status::DROPPED_PARTICIPANT) {
      --found;
    }
  }
  void onParticipantAuthentication(
      dds::DomainParticipant*,
      eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
    using Status = eprosima::fastrtps::rtps::ParticipantAuthenticationInfo::AUTHENTICATION_STATUS;
    if (info.status == Status::AUTHORIZED_PARTICIPANT) ++found;
  }
  std::atomic<int> found{0};

 private:
  const bool secured_;
};

std::string identity_of(int id) {
  return oscar::security_files::module_identity(fmt::format("p{}", id));
}

// One participant process: reports on `report` once it has discovered all others, then waits
// for SIGTERM.
[[noreturn]] void participate(const Options& o, int domain, int id, int report) {
  sigset_t term;
  sigemptyset(&term);
  sigaddset(&term, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &term, nullptr);
  dds::DomainParticipantQos qos;
  qos.name(fmt::format("bare-{}", id));
  qos.transport().use_builtin_transports = false;
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList = {"127.0.0.1"};
  qos.transport().user_transports.push_back(udp);
  if (o.shared_memory) {
    qos.transport().user_transports.push_back(
        std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
  }
  auto& wire = qos.wire_protocol();
  wire.participant_id = id;
  auto& builtin = wire.builtin;
  builtin.avoid_builtin_multicast = true;
  builtin.metatrafficMulticastLocatorList.clear();
  builtin.metatrafficUnicastLocatorList.clear();
  builtin.metatrafficUnicastLocatorList.push_back(loopback(metatraffic_port(domain, id)));
  wire.default_unicast_locator_list.push_back(loopback(metatraffic_port(domain, id) + 1));
  for (int peer = 0; peer < id; ++peer) {
    builtin.initialPeersList.push_back(loopback(metatraffic_port(domain, peer)));
  }
  builtin.discovery_config.leaseDuration = eprosima::fastrtps::Duration_t(kLeaseSeconds, 0);
  builtin.discovery_config.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(1, 0);
  builtin.discovery_config.initial_announcements.count =
      static_cast<std::uint32_t>(o.initial_announcements);
  if (!o.keystore.empty()) {
    for (auto& [property, value] :
         oscar::security_files::dds_security_properties(o.keystore, identity_of(id))) {
      qos.properties().properties().emplace_back(std::move(property), std::move(value));
    }
  }
  CountingListener listener(!o.keystore.empty());
  auto* factory = dds::DomainParticipantFactory::get_instance();
  auto* participant = factory->create_participant(domain, qos, &listener);
  if (!participant) {
    std::fprintf(stderr, "participant %d: cannot be created on domain %d\n", id, domain);
    _exit(1);
  }
  auto* type = new oscar::RawCdrType("bare::Bytes");
  type->auto_fill_type_object(false);
  type->auto_fill_type_information(false);
  dds::TypeSupport(type).register_type(participant);
  auto* publisher = participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  for (int e = 0; e < o.endpoints; ++e) {
    auto* topic = participant->create_topic(fmt::format("bare/{}/{}", id, e), "bare::Bytes",
                                            dds::TOPIC_QOS_DEFAULT);
    auto writer_qos = dds::DATAWRITER_QOS_DEFAULT;
    writer_qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    publisher->create_datawriter(topic, writer_qos);
  }
  // Reports 'j' once it has found every participant started before it (it has joined), 'c'
  // once it has found all. SIGTERM ends it also before (the run timed out).
  const timespec poll{0, 5'000'000};
  bool stopped = false;
  for (const auto& [seen, news] : {std::pair{id, 'j'}, std::pair{o.participants - 1, 'c'}}) {
    while (!stopped && listener.found.load() < seen) {
      stopped = sigtimedwait(&term, nullptr, &poll) == SIGTERM;
    }
    if (!stopped && write(report, &news, 1) != 1) _exit(1);
  }
  if (!stopped) {
    int signal = 0;
    sigwait(&term, &signal);
  }
  participant->delete_contained_entities();
  factory->delete_participant(participant);
  _exit(0);
}

// A system file naming one module per participant, and its keystore (`oscar security init`).
std::string make_keystore(int participants) {
  std::string yaml = "system: bench_discovery\nmodules:\n";
  for (int id = 0; id < participants; ++id) {
    const auto kernel =
        fmt::format("{{ type: bench_source, name: k{}, params: {{ type: Bool }} }}", id);
    yaml += fmt::format("  - {{ name: p{}, kernels: [ {} ] }}\n", id, kernel);
  }
  const auto file = oscar::test::temp_path("bench_discovery") + ".yaml";
  std::ofstream(file) << yaml;
  return oscar::test::make_bench_keystore(file, "bench_discovery");
}

double cpu_seconds(const std::vector<pid_t>& pids) {
  double sum = 0;
  for (const auto pid : pids) sum += oscar::test::cpu_seconds(pid);
  return sum;
}

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Kills the newest participant (pids.back()) o.rejoins times; each time, once the others have
// dropped it, starts it again with the same participant id and times until the successor has
// found every other one (ms). A successor that does not within o.timeout_s ends the rejoins.
std::vector<double> time_rejoins(const Options& o, int domain, const int report[2],
                                 std::vector<pid_t>& pids) {
  std::vector<double> ms;
  for (int r = 0; r < o.rejoins; ++r) {
    kill(pids.back(), SIGKILL);
    waitpid(pids.back(), nullptr, 0);
    // The lease runs from its last announcement (at most a second before the kill).
    std::this_thread::sleep_for(std::chrono::seconds(kLeaseSeconds + 1));
    const auto start = Clock::now();
    const pid_t pid = fork();
    if (pid == 0) {
      close(report[0]);
      participate(o, domain, o.participants - 1, report[1]);
    }
    pids.back() = pid;
    // It reports 'j' and then 'c' at once: every other participant started before it.
    char byte = 0;
    pollfd news{report[0], POLLIN, 0};
    while (byte != 'c' && ms_since(start) < 1000.0 * o.timeout_s) {
      if (poll(&news, 1, 100) == 1 && read(report[0], &byte, 1) != 1) break;
    }
    if (byte != 'c') {
      std::fprintf(stderr,
                   "rejoin %d: the successor did not find every other participant within %d s\n",
                   r + 1, o.timeout_s);
      break;
    }
    ms.push_back(ms_since(start));
  }
  return ms;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app("oscar bench discovery: what bare Fast DDS discovery costs N participants");
  app.add_option("--participants", o.participants, "participants, one process each")
      ->check(CLI::Range(2, 119));
  app.add_option("--endpoints", o.endpoints, "writers per participant")->check(CLI::Range(0, 50));
  app.add_option("--upkeep", o.upkeep_s, "seconds of discovery upkeep measured afterwards")
      ->check(CLI::PositiveNumber);
  app.add_option("--timeout", o.timeout_s, "seconds to wait for full discovery")
      ->check(CLI::PositiveNumber);
  app.add_option("--initial-announcements", o.initial_announcements,
                 "announcements a new participant sends 100 ms apart (Fast DDS: 5)")
      ->check(CLI::Range(1, 10));
  app.add_option("--at-a-time", o.at_a_time,
                 "start the next participant only while fewer than this many have not yet found "
                 "those before them (0: all at once)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--rejoins", o.rejoins,
                 "afterwards kill -9 the newest participant this often and time its successor "
                 "until it has found every other one")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--security", o.security,
               "with DDS Security (a keystore made here); found means authenticated");
  app.add_flag("--shared-memory", o.shared_memory, "shared memory for user data too, as OSCAR");
  app.add_flag("--json", o.json, "print one JSON line");
  CLI11_PARSE(app, argc, argv);
  if (o.security && o.endpoints != 0) {
    std::fprintf(
        stderr,
        "--security: the keystore's permissions allow no bare/ topics; add --endpoints 0\n");
    return 2;
  }
  if (o.rejoins > 0 && o.shared_memory) {
    std::fprintf(stderr,
                 "--rejoins: not with --shared-memory (a killed participant's segment "
                 "would stay in /dev/shm)\n");
    return 2;
  }
  if (o.security) o.keystore = make_keystore(o.participants);

  const int domain = oscar::test::test_domain();
  int report[2];
  if (pipe(report) != 0) return 1;
  std::vector<pid_t> pids;
  std::mutex pids_mutex;  // the watchdog kills what has been started
  const auto start = Clock::now();
  std::atomic<bool> timed_out{false};
  std::thread watchdog([&] {
    const auto until = start + std::chrono::seconds(o.timeout_s);
    while (Clock::now() < until && !timed_out.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    if (!timed_out.exchange(true)) {
      std::lock_guard lock(pids_mutex);
      for (const auto pid : pids) kill(pid, SIGTERM);
    }
  });
  // Started one after another; with --at-a-time K the next only while fewer than K have not
  // yet found those before them (as boot starts a host's modules, 8 at a time).
  int joined = 0, done = 0;
  const int at_a_time = o.at_a_time > 0 ? o.at_a_time : o.participants;
  pollfd news{report[0], POLLIN, 0};
  while (done < o.participants && !timed_out.load()) {
    while (static_cast<int>(pids.size()) < o.participants &&
           static_cast<int>(pids.size()) - joined < at_a_time) {
      const int id = static_cast<int>(pids.size());
      const pid_t pid = fork();
      if (pid == 0) {
        close(report[0]);
        participate(o, domain, id, report[1]);
      }
      std::lock_guard lock(pids_mutex);
      pids.push_back(pid);
    }
    if (poll(&news, 1, 100) != 1) continue;
    char byte = 0;
    if (read(report[0], &byte, 1) != 1) break;
    (byte == 'j' ? joined : done) += 1;
  }
  const auto discovered_ms = ms_since(start);
  const double discovery_cpu_s = cpu_seconds(pids);
  const bool complete = done == o.participants;
  double upkeep_cpu_per_s = 0;
  if (complete) {
    std::this_thread::sleep_for(std::chrono::seconds(o.upkeep_s));
    upkeep_cpu_per_s = (cpu_seconds(pids) - discovery_cpu_s) / o.upkeep_s;
  }
  timed_out = true;
  watchdog.join();
  const auto rejoin_ms = complete ? time_rejoins(o, domain, report, pids) : std::vector<double>{};
  close(report[1]);
  for (const auto pid : pids) kill(pid, SIGTERM);
  for (const auto pid : pids) waitpid(pid, nullptr, 0);
  close(report[0]);
  if (!o.keystore.empty()) std::filesystem::remove_all(o.keystore);
  using oscar::test::percentile;
  const auto slow =
      std::count_if(rejoin_ms.begin(), rejoin_ms.end(), [](double t) { return t >= 900; });
  const bool rejoined = static_cast<int>(rejoin_ms.size()) == o.rejoins;
  if (o.json) {
    std::printf(
        "{\"participants\":%d,\"endpoints\":%d,\"initial_announcements\":%d,\"at_a_time\":%d,"
        "\"complete\":%s,"
        "\"discovered\":%d,"
        "\"discovery_ms\":%.0f,\"discovery_cpu_s\":%.2f,\"upkeep_cpu_s_per_s\":%.3f,"
        "\"security\":%s,\"rejoins\":%zu,\"rejoin_ms_p50\":%.0f,\"rejoin_ms_p90\":%.0f,"
        "\"rejoin_ms_max\":%.0f,\"rejoins_900ms_or_more\":%td}\n",
        o.participants, o.endpoints, o.initial_announcements, o.at_a_time,
        complete ? "true" : "false", done, discovered_ms, discovery_cpu_s, upkeep_cpu_per_s,
        o.security ? "true" : "false", rejoin_ms.size(), percentile(rejoin_ms, 0.5),
        percentile(rejoin_ms, 0.9), percentile(rejoin_ms, 1), slow);
  } else {
    std::printf(
        "oscar bench discovery: %d bare Fast DDS participants, %d writers each%s\n"
        "  every one %s by every other: %s after %.0f ms (%d of %d complete)\n"
        "  CPU until then: %.2f s; discovery upkeep afterwards: %.3f CPU-s per second\n",
        o.participants, o.endpoints, o.security ? ", with DDS Security" : "",
        o.security ? "authenticated" : "discovered", complete ? "yes" : "NO", discovered_ms, done,
        o.participants, discovery_cpu_s, upkeep_cpu_per_s);
    if (o.rejoins > 0) {
      std::printf(
          "  rejoins (kill -9, started again after the lease): %zu of %d; the successor found "
          "every other one after p50 %.0f ms, p90 %.0f ms, max %.0f ms; %td took 900 ms or more\n",
          rejoin_ms.size(), o.rejoins, percentile(rejoin_ms, 0.5), percentile(rejoin_ms, 0.9),
          percentile(rejoin_ms, 1), slow);
    }
  }
  return complete && rejoined ? 0 : 1;
}
