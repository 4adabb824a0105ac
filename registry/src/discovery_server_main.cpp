// oscar-discovery-server: one of the Fast DDS discovery servers of a system whose network says
// `discovery: server` (docs/network.md). `oscar boot` starts it before anything else and stops
// it after everything else.
#include <cstdio>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/discovery_server.hpp"
#include "oscar/process_util.hpp"
#include "oscar/registry/system_spec.hpp"

int main(int argc, char** argv) {
  CLI::App app{"oscar-discovery-server: a discovery server the participants of a system use"};
  std::string file, host;
  int domain = -1;
  int index = 0;
  app.add_option("--system", file, "the system file")->required();
  app.add_option("--host", host, "the host it runs on (default: the system's first local host)");
  app.add_option("-d,--domain", domain, "DDS domain (default: the file's)");
  app.add_option("--index", index, "which of the network's discovery servers: 0 or 1");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);

  const auto signals = oscar::block_stop_signals();
  try {
    auto system = oscar::SystemSpec::load(file);
    if (domain >= 0) system.override_domain(domain);
    if (host.empty()) host = system.local_host().name;
    const auto network = oscar::NetworkConfig::for_host(system.root, host);
    if (network.discovery != oscar::Discovery::kServer) {
      throw std::invalid_argument(
          fmt::format("{}: the network does not say discovery: server", system.file));
    }
    const oscar::DiscoveryServer server(system.domain, network, index);
    std::printf("discovery server %d of domain %d on %s\n", index, system.domain,
                server.locator().c_str());
    std::fflush(stdout);
    while (!oscar::wait_for_stop(signals, std::chrono::seconds(1))) {
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-discovery-server: %s\n", e.what());
    return 2;
  }
}
