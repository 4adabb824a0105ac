// oscar-security: the DDS Security keystore of a system (docs/security.md).
//   oscar security init SYSTEM.yaml [--keystore DIR]    create it or bring it up to date
//   oscar security check SYSTEM.yaml [--keystore DIR]   0: sound, 1: warnings, 2: errors
//   oscar security list (SYSTEM.yaml | --keystore DIR) [--json]
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <oscar/command_line.hpp>

#include <algorithm>
#include <iostream>
#include <stdexcept>

#include "keystore.hpp"
#include "oscar/registry/system_spec.hpp"

namespace {

namespace fs = std::filesystem;
using oscar::security::Finding;

// --keystore, else the system file's `security: keystore:`.
fs::path keystore_of(const std::string& flag, const oscar::SystemSpec* system) {
  if (!flag.empty()) return fs::absolute(flag);
  if (system && system->security && !system->security->keystore.empty()) {
    return system->security->keystore;
  }
  throw std::invalid_argument(
      system ? fmt::format("{} has no security: keystore:; give --keystore DIR", system->file)
             : "give SYSTEM.yaml or --keystore DIR");
}

std::string date(std::chrono::system_clock::time_point t) {
  const std::time_t tt = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char text[16];
  std::strftime(text, sizeof text, "%Y-%m-%d", &tm);
  return text;
}

int init(const oscar::SystemSpec& system, const fs::path& dir) {
  const auto said = oscar::security::init_keystore(system, dir);
  std::cout << fmt::format("keystore {} for system '{}':\n", dir.string(), system.name);
  for (const auto& line : said) std::cout << "  " << line << "\n";
  return 0;
}

int check(const oscar::SystemSpec& system, const fs::path& dir) {
  const auto found = oscar::security::check_keystore(system, dir);
  int errors = 0;
  for (const auto& f : found) {
    const bool error = f.level == Finding::Level::kError;
    errors += error ? 1 : 0;
    std::cout << (error ? "error: " : "warning: ") << f.text << "\n";
  }
  const auto warnings = static_cast<int>(found.size()) - errors;
  std::cout << fmt::format("keystore {}: {} error{}, {} warning{}\n", dir.string(), errors,
                           errors == 1 ? "" : "s", warnings, warnings == 1 ? "" : "s");
  return errors > 0 ? 2 : (warnings > 0 ? 1 : 0);
}

int list(const fs::path& dir, bool json) {
  const auto identities = oscar::security::list_keystore(dir);
  if (json) {
    auto out = nlohmann::json::array();
    for (const auto& i : identities) {
      nlohmann::json j{{"identity", i.name}, {"subject", i.subject}, {"publish", i.publish}};
      j["expires"] = i.subject.empty() ? "" : date(i.not_after);  // known once the cert is read
      if (!i.problem.empty()) j["problem"] = i.problem;
      out.push_back(std::move(j));
    }
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  std::size_t name_width = 8, subject_width = 7;
  for (const auto& i : identities) {
    name_width = std::max(name_width, i.name.size());
    subject_width = std::max(subject_width, i.subject.size());
  }
  std::cout << fmt::format("{:<{}}  {:<{}}  {:<10}  {}\n", "IDENTITY", name_width, "SUBJECT",
                           subject_width, "EXPIRES", "PUBLISHES");
  for (const auto& i : identities) {
    std::string publishes = i.problem.empty() ? "" : "! " + i.problem;
    if (i.problem.empty()) {
      for (const auto& t : i.publish) publishes += (publishes.empty() ? "" : ", ") + t;
      if (publishes.empty()) publishes = "(nothing)";
    }
    std::cout << fmt::format("{:<{}}  {:<{}}  {:<10}  {}\n", i.name, name_width, i.subject,
                             subject_width, i.subject.empty() ? "?" : date(i.not_after), publishes);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "oscar security: the DDS Security keystore of a system: CAs, a key and certificate per "
      "identity, governance and permissions derived from the system file (docs/security.md)"};
  app.require_subcommand(1);
  std::string system_file, keystore;
  bool json = false;
  auto* init_cmd = app.add_subcommand(
      "init", "create the keystore or bring it up to date with the system file (idempotent)");
  auto* check_cmd = app.add_subcommand(
      "check",
      "verify certificates, signatures, expiry and that the keystore matches the system "
      "file; exit 0 when sound, 1 with warnings only, 2 with errors");
  auto* list_cmd =
      app.add_subcommand("list", "the identities: subject, expiry, what each may publish on");
  for (auto* cmd : {init_cmd, check_cmd}) {
    cmd->add_option("system", system_file, "the system file")->required();
  }
  list_cmd->add_option("system", system_file, "the system file (for its security: keystore:)");
  list_cmd->add_flag("--json", json, "as JSON");
  for (auto* cmd : {init_cmd, check_cmd, list_cmd}) {
    cmd->add_option("--keystore", keystore,
                    "the keystore folder (default: the system file's security: keystore:)");
  }
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  const auto* command = app.get_subcommands().front();
  try {
    std::optional<oscar::SystemSpec> system;
    if (!system_file.empty()) system = oscar::SystemSpec::load(system_file);
    const auto dir = keystore_of(keystore, system ? &*system : nullptr);
    if (command == init_cmd) return init(*system, dir);
    if (command == check_cmd) return check(*system, dir);
    return list(dir, json);
  } catch (const std::exception& e) {
    std::cerr << "oscar security " << command->get_name() << ": " << e.what() << "\n";
    return 2;
  }
}
