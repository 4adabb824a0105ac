#include "oscar/registry/running_systems.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "oscar/dds_participant.hpp"
#include "oscar/network.hpp"

namespace oscar {
namespace {

namespace fs = std::filesystem;

std::string record_path(int domain) {
  return fmt::format("{}/domain-{}.json", running_systems_dir(), domain);
}

// When the process started, in clock ticks after boot (field 22 of /proc/PID/stat): with the pid
// it names one process, since pids are reused.
long long start_ticks(pid_t pid) {
  std::ifstream in(fmt::format("/proc/{}/stat", pid));
  std::string stat;
  if (!std::getline(in, stat)) return -1;
  const auto close = stat.rfind(')');  // the command name may hold spaces and parentheses
  if (close == std::string::npos) return -1;
  std::istringstream fields(stat.substr(close + 2));
  std::string field;
  for (int i = 3; i <= 22 && fields >> field; ++i) {
    if (i == 22) return std::stoll(field);
  }
  return -1;
}

bool boot_alive(const RunningSystem& s) {
  return s.boot_pid > 0 && start_ticks(s.boot_pid) == s.boot_started_ticks;
}

std::optional<RunningSystem> read_record(const fs::path& path) {
  std::ifstream in(path);
  const auto j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return std::nullopt;
  RunningSystem s;
  s.domain = j.value("domain", -1);
  s.system = j.value("system", "");
  s.file = j.value("file", "");
  s.log_dir = j.value("log_dir", "");
  s.keystore = j.value("keystore", "");
  s.boot_pid = j.value("boot_pid", 0);
  s.started = j.value("started", 0LL);
  s.boot_started_ticks = j.value("boot_started_ticks", -1LL);
  if (s.domain < 0) return std::nullopt;
  return s;
}

// The live record at `path`; a stale or unreadable one is removed.
std::optional<RunningSystem> live_record(const fs::path& path) {
  auto s = read_record(path);
  if (s && boot_alive(*s)) return s;
  std::error_code ec;
  fs::remove(path, ec);
  return std::nullopt;
}

// Whose a discovered member is: "the system 'busy' (boot pid 1234 on host1)" from its instance
// (boot_main.cpp makes it "<system>@<host>:<boot pid>:<start ms>").
std::string whose(const std::string& instance) {
  if (instance.empty()) return "processes started by hand";
  const auto at = instance.rfind('@');
  const auto pid_at = instance.find(':', at);
  const auto ms_at = instance.find(':', pid_at + 1);
  if (at == std::string::npos || pid_at == std::string::npos || ms_at == std::string::npos) {
    return fmt::format("the system instance '{}'", instance);
  }
  return fmt::format("the system '{}' (boot pid {} on {})", instance.substr(0, at),
                     instance.substr(pid_at + 1, ms_at - pid_at - 1),
                     instance.substr(at + 1, pid_at - at - 1));
}

}  // namespace

std::string RunningSystem::describe() const {
  std::error_code ec;
  auto shown = fs::relative(file, fs::current_path(ec), ec).string();
  if (ec || shown.empty() || shown.starts_with("../..")) shown = file;
  return fmt::format("{} (domain {}, {}, boot pid {})", system, domain, shown, boot_pid);
}

std::string running_systems_dir() {
  const char* env = std::getenv("OSCAR_SYSTEMS_DIR");
  return env && *env ? env : "/tmp/oscar/systems";
}

std::vector<RunningSystem> running_systems() {
  std::vector<RunningSystem> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(running_systems_dir(), ec)) {
    const auto name = e.path().filename().string();
    if (!name.starts_with("domain-") || e.path().extension() != ".json") continue;
    if (auto s = live_record(e.path())) out.push_back(std::move(*s));
  }
  std::sort(out.begin(), out.end(),
            [](const auto& a, const auto& b) { return a.domain < b.domain; });
  return out;
}

std::optional<RunningSystem> running_system(int domain) {
  if (!fs::exists(record_path(domain))) return std::nullopt;
  return live_record(record_path(domain));
}

bool is_system_member(const std::string& participant_name) {
  return participant_name == "oscar-registry" || participant_name.starts_with("oscar-monitor:") ||
         participant_name.starts_with("oscar:");
}

std::string other_systems_on_domain(const DdsParticipant& participant) {
  const auto own = system_instance_from_env();
  std::map<std::string, std::set<std::string>> others;  // by instance
  for (const auto& p : participant.discovered_participants()) {
    if (is_system_member(p.name) && p.system_instance != own) {
      others[p.system_instance].insert(p.name);
    }
  }
  std::vector<std::string> parts;
  for (const auto& [instance, names] : others) {
    parts.push_back(fmt::format("{}: {}", whose(instance), fmt::join(names, ", ")));
  }
  return fmt::format("{}", fmt::join(parts, "; "));
}

std::string other_systems_in_full(const DdsParticipant& participant) {
  auto others = other_systems_on_domain(participant);
  for (int i = 0; i < 60 && others.find("oscar-registry") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    others = other_systems_on_domain(participant);
  }
  return others;
}

std::string domain_in_use(int domain, const std::string& others) {
  return fmt::format(
      "domain {} is in use by {}; stop it (oscar shutdown -d {}) or boot on another domain "
      "(--domain N)",
      domain, others, domain);
}

RunningSystemRecord::RunningSystemRecord(const RunningSystem& system)
    : path_(record_path(system.domain)) {
  std::error_code ec;
  fs::create_directories(running_systems_dir(), ec);
  const auto text = nlohmann::json{{"domain", system.domain},
                                   {"system", system.system},
                                   {"file", fs::absolute(system.file).string()},
                                   {"log_dir", system.log_dir},
                                   {"keystore", system.keystore},
                                   {"boot_pid", system.boot_pid},
                                   {"started", system.started},
                                   {"boot_started_ticks", start_ticks(system.boot_pid)}}
                        .dump(2) +
                    "\n";
  // O_EXCL: of two boots started at once on one domain, exactly one gets the record.
  for (int attempt = 0; attempt < 2; ++attempt) {
    const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd >= 0) {
      const bool written =
          ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
      ::close(fd);
      if (!written) {
        fs::remove(path_, ec);
        throw std::runtime_error(fmt::format("cannot write {}", path_));
      }
      return;
    }
    if (errno != EEXIST) {
      throw std::runtime_error(fmt::format("cannot write {}: {}", path_, std::strerror(errno)));
    }
    if (auto other = live_record(path_)) {
      throw std::runtime_error(
          domain_in_use(system.domain, "the running system " + other->describe()));
    }
  }
  throw std::runtime_error(fmt::format("cannot take {}: another boot keeps writing it", path_));
}

RunningSystemRecord::~RunningSystemRecord() {
  // Only our own: a record some later boot wrote after ours was taken away stays.
  const auto mine = read_record(path_);
  if (mine && mine->boot_pid == getpid()) {
    std::error_code ec;
    fs::remove(path_, ec);
  }
}

}  // namespace oscar
