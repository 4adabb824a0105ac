#include "oscar/registry/host_check.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oscar/module.hpp"
#include "oscar/process_util.hpp"
#include "oscar/registry/launch_command.hpp"

#ifndef OSCAR_VERSION
#error "OSCAR_VERSION is defined by registry/CMakeLists.txt"
#endif

namespace oscar {
namespace {

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) out.push_back(line);
  }
  return out;
}

bool contains(const std::string& text, const char* part) {
  return text.find(part) != std::string::npos;
}

// ssh's own complaint: its last line that is no warning about known hosts.
std::string ssh_said(const std::string& output) {
  const auto lines = lines_of(output);
  for (auto it = lines.rbegin(); it != lines.rend(); ++it) {
    if (!it->starts_with("Warning: Permanently added")) return *it;
  }
  return "no message";
}

}  // namespace

std::string oscar_version() { return OSCAR_VERSION; }

std::string content_fingerprint(const std::string& content) {
  std::uint64_t hash = 14695981039346656037ull;
  for (const unsigned char c : content) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  return fmt::format("{:016x}", hash);
}

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(fmt::format("{}: cannot read the file", path));
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

std::optional<std::string> zero_copy_unavailable() {
  if (!OSCAR_ZERO_COPY) {
    return "zero_copy: this OSCAR was built without iceoryx (install the Debian package "
           "libiceoryx-posh-dev and build it again)";
  }
  if (!find_on_path("iox-roudi")) {
    return "zero_copy: iox-roudi is not installed on this host (Debian package iceoryx)";
  }
  return std::nullopt;
}

std::string check_banner() { return "oscar-monitor " + oscar_version(); }

std::vector<std::string> check_this_host(const std::string& file, const std::string& host,
                                         const std::string& expected_fingerprint,
                                         const std::vector<std::string>& plugin_path,
                                         const ProgramPath& program_path) {
  if (!std::filesystem::exists(file)) {
    return {fmt::format("the system file {} is not there (copy it to the same path)", file)};
  }
  if (content_fingerprint(read_text_file(file)) != expected_fingerprint) {
    return {
        fmt::format("the system file {} differs from boot's (copy boot's to the same path)", file)};
  }
  std::vector<std::string> problems;
  try {
    const auto system = SystemSpec::load(file);  // its relative paths resolve here as at boot
    system.host(host);
    if (system.zero_copy) {
      if (auto problem = zero_copy_unavailable()) problems.push_back(std::move(*problem));
    }
    for (const auto& m : system.modules) {
      if (m.spec.host != host) continue;  // standby modules too: they may be started there
      const auto program = program_path(m.program);
      if (access(program.c_str(), X_OK) != 0) {
        problems.push_back(
            fmt::format("module '{}': missing program {} (install this OSCAR build "
                        "at the same path)",
                        m.spec.name, program));
        continue;
      }
      if (m.program != "oscar-run") continue;  // the others link their kernel in
      try {
        Module built(m.spec, plugin_path);  // loads its plugins; no DDS, nothing started
      } catch (const std::exception& e) {
        problems.push_back(fmt::format("module '{}': {}", m.spec.name, e.what()));
      }
    }
  } catch (const std::exception& e) {
    problems.push_back(e.what());
  }
  return problems;
}

std::vector<std::string> host_check_command(const HostSpec& host, const std::string& file,
                                            const std::string& monitor) {
  return on_host(host, {monitor, "--system", file, "--host", host.name, "--check",
                        content_fingerprint(read_text_file(file))});
}

std::vector<std::string> copy_system_file_command(const HostSpec& host, const std::string& file) {
  return on_host(host, {"sh", "-c",
                        "mkdir -p \"$(dirname \"$1\")\" && cat > \"$1.oscar-copy\" && "
                        "mv \"$1.oscar-copy\" \"$1\"",
                        "oscar-copy", file});
}

std::optional<std::string> explain_host_check(const HostSpec& host, const std::string& monitor,
                                              int exit_code, const std::string& output) {
  const auto who = fmt::format("host '{}' ({})", host.name, host.ssh);
  const auto lines = lines_of(output);
  std::size_t banner = 0;
  while (banner < lines.size() && !lines[banner].starts_with("oscar-monitor ")) ++banner;
  if (banner == lines.size()) {
    if (exit_code == -1) return fmt::format("{}: unreachable: no answer in time", who);
    // 255 is ssh's own failure; the remote command's codes are its own.
    if (exit_code == 255 && contains(output, "Permission denied")) {
      return fmt::format(
          "{}: authentication refused ({}); is your key in its "
          "authorized_keys, or name it with ssh_options: [IdentityFile=...]?",
          who, ssh_said(output));
    }
    if (exit_code == 255 && (contains(output, "Host key verification failed") ||
                             contains(output, "IDENTIFICATION HAS CHANGED"))) {
      return fmt::format("{}: its host key is not trusted ({}); add it to known_hosts", who,
                         ssh_said(output));
    }
    if (exit_code == 255) return fmt::format("{}: unreachable ({})", who, ssh_said(output));
    if (exit_code == 126) {
      return fmt::format("{}: cannot run {} there, it is not executable ({})", who, monitor,
                         ssh_said(output));
    }
    if (exit_code == 127 || contains(output, "No such file")) {
      return fmt::format("{}: missing program {} (install this OSCAR build, {}, at the same path)",
                         who, monitor, oscar_version());
    }
    if (contains(output, "--check")) {
      return fmt::format(
          "{}: version mismatch: its oscar-monitor knows no --check (an OSCAR older "
          "than {}); install OSCAR {} there",
          who, oscar_version(), oscar_version());
    }
    return fmt::format("{}: the check failed with exit code {}: {}", who, exit_code,
                       fmt::join(lines, " | "));
  }
  if (lines[banner] != check_banner()) {
    return fmt::format("{}: version mismatch: {} there, {} here; install OSCAR {} there", who,
                       lines[banner], check_banner(), oscar_version());
  }
  if (exit_code == 0) return std::nullopt;
  const std::vector<std::string> problems(lines.begin() + static_cast<long>(banner) + 1,
                                          lines.end());
  return fmt::format("{}: {}", who,
                     problems.empty() ? fmt::format("the check failed with exit code {}", exit_code)
                                      : fmt::format("{}", fmt::join(problems, "; ")));
}

}  // namespace oscar
