// oscar-registry: holds the system graph and keeps the system running (docs/boot.md).
#include <csignal>
#include <cstdio>
#include <thread>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/process_util.hpp"
#include "oscar/registry/registry.hpp"
#include "oscar/security_files.hpp"
#include "oscar/shared_memory.hpp"

int main(int argc, char** argv) {
  CLI::App app{"oscar-registry: boots a system through its monitors and restarts failed modules"};
  std::string file, host;
  int domain = -1;
  app.add_option("--system", file, "the system file")->required();
  app.add_option("--host", host, "the host it runs on (default: the system's first local host)");
  app.add_option("-d,--domain", domain, "DDS domain (default: the file's)");
  std::string journal;
  app.add_option("--journal", journal,
                 "where to keep what a registry after this one needs (docs/boot.md)");
  bool recover = false;
  app.add_flag("--recover", recover,
               "a registry before this one died: adopt the modules the monitors run, start only "
               "the others (oscar boot passes it when it restarts a registry)");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);

  auto signals = oscar::block_stop_signals();
  spdlog::set_pattern("%H:%M:%S.%e %^%-5l%$ %v");
  try {
    auto system = oscar::SystemSpec::load(file);
    if (domain >= 0) system.override_domain(domain);
    if (host.empty()) host = system.local_host().name;
    int code = 0;
    {
      // With discovery servers, the registry learns only of the participants it shares a topic
      // with (every module, monitor and tool shares its configuration or registry topics), not
      // of the modules' cue endpoints (docs/network.md).
      oscar::DdsParticipant participant(system.domain, "oscar-registry",
                                        system.network_for(host, oscar::security_files::kRegistry),
                                        oscar::DiscoveryScope::kSharedTopics);
      oscar::Registry registry(system, participant, journal, recover);
      std::thread signal_waiter([&] {
        int sig = 0;
        sigwait(&signals, &sig);
        registry.stop();
      });
      try {
        if (!registry.run()) code = oscar::kHandOverExit;
      } catch (const oscar::DomainInUse& e) {
        std::fprintf(stderr, "oscar-registry: %s\n", e.what());
        code = oscar::kDomainInUseExit;
      }
      pthread_kill(signal_waiter.native_handle(), SIGTERM);
      signal_waiter.join();
    }
    // Its participant is gone: what it and the system's ended processes left goes too (the
    // monitors do the same; whoever exits last leaves nothing behind).
    oscar::remove_files_of_dead_processes(system.domain);
    return code;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar-registry: %s\n", e.what());
    return 2;
  }
}
