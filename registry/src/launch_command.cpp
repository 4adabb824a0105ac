#include "oscar/registry/launch_command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace oscar {

std::string shell_quote(const std::string& word) {
  if (!word.empty() && word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                              "0123456789_-./:=@,+%") == std::string::npos) {
    return word;
  }
  std::string out = "'";
  for (char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::vector<std::string> on_host(const HostSpec& host, const std::vector<std::string>& argv) {
  switch (host.kind) {
    case HostSpec::Kind::kLocal:
      return argv;
    case HostSpec::Kind::kNetns: {
      std::vector<std::string> out{"ip", "netns", "exec", host.netns};
      out.insert(out.end(), argv.begin(), argv.end());
      return out;
    }
    case HostSpec::Kind::kSsh: {
      std::string remote;
      for (const auto& a : argv) {
        if (!remote.empty()) remote += ' ';
        remote += shell_quote(a);
      }
      // ssh takes the first value it gets for an option: the host's own options come before
      // the defaults they may override (not BatchMode: nobody could type a password).
      std::vector<std::string> out{"ssh", "-o", "BatchMode=yes"};
      for (const auto& o : host.ssh_options) out.insert(out.end(), {"-o", o});
      // A host that does not answer fails the check in 10 s; a connection that stops carrying
      // anything ends within 3 s, and its monitor then stops the host's modules.
      out.insert(out.end(), {"-o", "ConnectTimeout=10", "-o", "ServerAliveInterval=1", "-o",
                             "ServerAliveCountMax=3", "-T", host.ssh, "--", remote});
      return out;
    }
  }
  return argv;
}

std::vector<std::string> module_command(const SystemSpec& system, const SystemModule& module,
                                        unsigned incarnation, const ProgramPath& program_path,
                                        const std::string& log_dir) {
  std::vector<std::string> argv;
  if (module.debug.gdbserver_port > 0) {
    argv = {"gdbserver", fmt::format("127.0.0.1:{}", module.debug.gdbserver_port)};
  } else if (module.debug.valgrind) {
    argv = {"valgrind", fmt::format("--log-file={}/{}.{}.valgrind.log", log_dir, module.spec.name,
                                    incarnation)};
    argv.insert(argv.end(), module.debug.valgrind_args.begin(), module.debug.valgrind_args.end());
  }
  argv.insert(argv.end(), {program_path(module.program), system.file, "--module", module.spec.name,
                           "--incarnation", std::to_string(incarnation), "--domain",
                           std::to_string(module.spec.domain.value_or(system.domain))});
  return argv;
}

std::vector<std::string> launch_command(const SystemSpec& system, const std::string& host,
                                        const std::string& module, unsigned incarnation,
                                        const std::string& restore, const std::string& log_dir,
                                        const ProgramPath& program_path) {
  const auto found = std::find_if(system.modules.begin(), system.modules.end(),
                                  [&](const SystemModule& m) { return m.spec.name == module; });
  if (found == system.modules.end()) {
    throw std::invalid_argument(fmt::format(
        "refused to start '{}': {} has no module of that name (a monitor starts only the "
        "modules of its system file)",
        module, system.file));
  }
  if (found->spec.host != host) {
    throw std::invalid_argument(
        fmt::format("refused to start '{}': {} puts it on host '{}', this monitor watches '{}'",
                    module, system.file, found->spec.host, host));
  }
  auto argv = module_command(system, *found, incarnation, program_path, log_dir);
  if (!restore.empty()) argv.insert(argv.end(), {"--restore", restore});
  return argv;
}

}  // namespace oscar
