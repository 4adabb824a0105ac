#include "restore_text.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

namespace oscar::internal {

std::string restore_text(const ModuleState& last) {
  YAML::Emitter out;
  out << YAML::Flow << YAML::BeginMap;
  for (const auto& k : last.kernels()) {
    out << YAML::Key << k.name() << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "mode" << YAML::Value
        << (k.mode() == "continuous"    ? fmt::format("continuous:{}ns", k.cycle_ns())
            : k.mode() == "deactivated" ? std::string("deactivated")
            : k.trigger() == "default" || k.trigger().empty() ? std::string("single_step")
                                                              : "single_step:" + k.trigger());
    out << YAML::Key << "stub" << YAML::Value << k.stub();
    out << YAML::Key << "params" << YAML::Value << YAML::Load(k.params());
    out << YAML::Key << "inputs" << YAML::Value << YAML::BeginMap;
    for (const auto& wire : k.inputs()) {
      const auto eq = wire.find('=');
      out << YAML::Key << wire.substr(0, eq) << YAML::Value << wire.substr(eq + 1);
    }
    out << YAML::EndMap << YAML::EndMap;
  }
  out << YAML::EndMap;
  return out.c_str();
}

const std::string& RestoreTextCache::of(const ModuleState& last) {
  // Every field restore_text() reads, each ended by a character none of them holds.
  std::string source;
  for (const auto& k : last.kernels()) {
    source += fmt::format("{}\x1f{}\x1f{}\x1f{}\x1f{}\x1f{}\x1f", k.name(), k.mode(), k.cycle_ns(),
                          k.trigger(), k.stub(), k.params());
    for (const auto& wire : k.inputs()) (source += wire) += '\x1f';
    source += '\x1e';
  }
  if (source != source_ || text_.empty()) {
    text_ = restore_text(last);
    source_ = std::move(source);
  }
  return text_;
}

}  // namespace oscar::internal
