#include "registry_journal.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

namespace oscar::internal {
namespace {

// The first key of every journal; a file without it (or of another version) is not read.
constexpr const char* kVersionKey = "oscar_registry_journal";
constexpr int kVersion = 2;
// The last key: a file cut short (a full disk) lacks it, whatever else parses.
constexpr const char* kEndKey = "end";

template <class T>
T field(const YAML::Node& node, const char* key, const std::string& where) {
  const auto value = node[key];
  if (!value) throw std::invalid_argument(fmt::format("{}: '{}' is missing", where, key));
  try {
    return value.as<T>();
  } catch (const YAML::Exception&) {
    const char* kind = std::is_same_v<T, std::string> ? "text"
                       : std::is_same_v<T, bool>      ? "true or false"
                                                      : "number";
    throw std::invalid_argument(
        fmt::format("{}: '{}' is not {} {}", where, key, std::is_same_v<T, bool> ? "" : "a", kind));
  }
}

}  // namespace

std::string RegistryJournal::to_yaml() const {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << kVersionKey << YAML::Value << kVersion;
  out << YAML::Key << "written_ns" << YAML::Value << written;
  out << YAML::Key << "modules" << YAML::Value << YAML::BeginSeq;
  for (const auto& m : modules) {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << m.name;
    out << YAML::Key << "incarnation" << YAML::Value << m.incarnation;
    out << YAML::Key << "restore" << YAML::Value << YAML::DoubleQuoted << m.restore;
    out << YAML::Key << "restarts" << YAML::Value << m.restarts;
    out << YAML::Key << "counted_ns" << YAML::Value << YAML::Flow << m.counted;
    out << YAML::Key << "last_failure" << YAML::Value << YAML::DoubleQuoted << m.last_failure;
    out << YAML::Key << "status" << YAML::Value << m.status;
    out << YAML::Key << "replaced_by" << YAML::Value << YAML::DoubleQuoted << m.replaced_by;
    out << YAML::Key << "restart_requested" << YAML::Value << m.restart_requested;
    out << YAML::Key << "restart_at_ns" << YAML::Value << m.restart_at;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << kEndKey << YAML::Value << true;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

RegistryJournal RegistryJournal::parse(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(
        fmt::format("{}: not a registry journal (not YAML: {})", file, e.msg));
  }
  if (!root.IsMap() || !root[kVersionKey]) {
    throw std::invalid_argument(
        fmt::format("{}: not a registry journal (no '{}' key)", file, kVersionKey));
  }
  if (field<int>(root, kVersionKey, file) != kVersion) {
    throw std::invalid_argument(fmt::format("{}: journal version {} (this registry reads {})", file,
                                            root[kVersionKey].as<std::string>(), kVersion));
  }
  if (!root[kEndKey]) {
    throw std::invalid_argument(
        fmt::format("{}: the journal is cut short (no '{}' key at its end)", file, kEndKey));
  }
  RegistryJournal j;
  j.written = field<Stamp>(root, "written_ns", file);
  const auto modules = root["modules"];
  if (!modules || !modules.IsSequence()) {
    throw std::invalid_argument(fmt::format("{}: 'modules' is not a list", file));
  }
  for (std::size_t i = 0; i < modules.size(); ++i) {
    const auto& n = modules[i];
    const auto where = fmt::format("{}: modules[{}]", file, i);
    if (!n.IsMap()) throw std::invalid_argument(where + ": not a map");
    JournalModule m;
    m.name = field<std::string>(n, "name", where);
    m.incarnation = field<unsigned>(n, "incarnation", where);
    m.restore = field<std::string>(n, "restore", where);
    m.restarts = field<unsigned>(n, "restarts", where);
    const auto counted = n["counted_ns"];
    if (!counted || !counted.IsSequence()) {
      throw std::invalid_argument(where + ": 'counted_ns' is not a list");
    }
    for (const auto& c : counted) m.counted.push_back(c.as<Stamp>());
    m.last_failure = field<std::string>(n, "last_failure", where);
    m.status = field<std::string>(n, "status", where);
    m.replaced_by = field<std::string>(n, "replaced_by", where);
    m.restart_requested = field<bool>(n, "restart_requested", where);
    m.restart_at = field<Stamp>(n, "restart_at_ns", where);
    j.modules.push_back(std::move(m));
  }
  return j;
}

void RegistryJournal::write(const std::string& file) const {
  const auto temporary = file + ".tmp";
  {
    std::ofstream out(temporary, std::ios::trunc);
    out << to_yaml();
    out.flush();
    if (!out) {
      throw std::runtime_error(fmt::format("{}: cannot write the registry journal: {}", temporary,
                                           std::strerror(errno)));
    }
  }
  if (std::rename(temporary.c_str(), file.c_str()) != 0) {
    throw std::runtime_error(
        fmt::format("{}: cannot replace the registry journal: {}", file, std::strerror(errno)));
  }
}

std::optional<RegistryJournal> RegistryJournal::read(const std::string& file) {
  std::ifstream in(file);
  if (!in) return std::nullopt;
  std::stringstream text;
  text << in.rdbuf();
  return parse(text.str(), file);
}

}  // namespace oscar::internal
