#include "oscar/module_spec.hpp"

#include <algorithm>
#include <filesystem>
#include <set>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oscar/security_files.hpp"
#include "oscar/time.hpp"

namespace oscar {
namespace {

[[noreturn]] void fail(const std::string& at, const std::string& message) {
  throw std::invalid_argument(at + ": " + message);
}

std::string scalar(const YAML::Node& node, const std::string& file, const std::string& what) {
  if (!node || !node.IsScalar() || node.Scalar().empty()) {
    fail(node ? yaml_where(file, node) : file, what + " must be a non-empty string");
  }
  return node.Scalar();
}

bool is_identifier(const std::string& s) {
  return !s.empty() && !std::isdigit(static_cast<unsigned char>(s[0])) &&
         std::all_of(s.begin(), s.end(), [](char c) {
           return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
         });
}

InputWiring parse_wiring(const YAML::Node& node, const std::string& file, const std::string& what) {
  InputWiring w;
  if (node.IsScalar()) {
    w.source = node.Scalar();
  } else if (node.IsMap()) {
    check_yaml_keys(node, file, what, {"source", "transfer", "depth"});
    if (node["source"]) w.source = scalar(node["source"], file, what + ".source");
    try {
      if (node["transfer"]) w.transfer = parse_transfer(node["transfer"].as<std::string>());
      if (node["depth"]) w.depth = node["depth"].as<std::size_t>();
    } catch (const std::exception& e) {
      fail(yaml_where(file, node), what + ": " + e.what());
    }
  } else {
    fail(yaml_where(file, node), what + ": expected 'kernel/channel' or {source, transfer, depth}");
  }
  const auto slash = w.source.find('/');
  if (!w.source.empty() &&
      (slash == std::string::npos || slash == 0 || slash + 1 == w.source.size() ||
       w.source.find('/', slash + 1) != std::string::npos)) {
    fail(yaml_where(file, node),
         fmt::format("{}: source '{}' must be '<kernel>/<channel>'", what, w.source));
  }
  if (w.depth && *w.depth == 0) fail(yaml_where(file, node), what + ": depth must be at least 1");
  return w;
}

KernelSpec parse_kernel(const YAML::Node& node, const std::string& file, std::size_t index) {
  const auto what = fmt::format("kernels[{}]", index);
  if (!node.IsMap()) fail(yaml_where(file, node), what + ": expected a map with type and name");
  check_yaml_keys(node, file, what, {"type", "name", "params", "inputs", "mode"});
  KernelSpec k;
  k.where = yaml_where(file, node);
  k.type = scalar(node["type"], file.empty() ? k.where : file, what + ".type");
  k.name = node["name"] ? scalar(node["name"], file, what + ".name") : k.type;
  if (!is_identifier(k.name)) {
    fail(k.where, fmt::format("{}: kernel name '{}' must be an identifier", what, k.name));
  }
  k.params = node["params"] ? YAML::Clone(node["params"]) : YAML::Node();
  if (k.params && !k.params.IsNull() && !k.params.IsMap()) {
    fail(yaml_where(file, node["params"]), what + ".params: expected a map of name: value");
  }
  if (const auto inputs = node["inputs"]) {
    if (!inputs.IsMap()) fail(yaml_where(file, inputs), what + ".inputs: expected a map");
    // The short form (docs/boot.md) puts `transfer:`/`depth:` beside the inputs: it applies to all.
    std::optional<Transfer> all_transfer;
    std::optional<std::size_t> all_depth;
    for (const auto& kv : inputs) {
      const auto key = kv.first.as<std::string>();
      try {
        if (key == "transfer") all_transfer = parse_transfer(kv.second.as<std::string>());
        if (key == "depth") all_depth = kv.second.as<std::size_t>();
      } catch (const std::exception& e) {
        fail(yaml_where(file, kv.second), fmt::format("{}.inputs.{}: {}", what, key, e.what()));
      }
    }
    for (const auto& kv : inputs) {
      const auto key = kv.first.as<std::string>();
      if (key == "transfer" || key == "depth") continue;
      auto w = parse_wiring(kv.second, file, fmt::format("{}.inputs.{}", what, key));
      if (!w.transfer) w.transfer = all_transfer;
      if (!w.depth) w.depth = all_depth;
      k.inputs[key] = std::move(w);
    }
  }
  if (node["mode"]) {
    try {
      k.mode = ModeSpec::parse(node["mode"]);
    } catch (const std::invalid_argument& e) {
      fail(yaml_where(file, node["mode"]), what + ".mode: " + e.what());
    }
  }
  return k;
}

}  // namespace

void check_yaml_keys(const YAML::Node& map, const std::string& file, const std::string& what,
                     std::initializer_list<const char*> allowed) {
  for (const auto& kv : map) {
    const auto key = kv.first.as<std::string>();
    if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) {
      fail(yaml_where(file, kv.first),
           fmt::format("{}: unknown key '{}' (allowed: {})", what, key, fmt::join(allowed, ", ")));
    }
  }
}

std::string yaml_where(const std::string& file, const YAML::Node& node) {
  const auto mark = node.Mark();
  if (mark.line < 0) return file;
  return fmt::format("{}:{}", file, mark.line + 1);
}

YAML::Node load_yaml_file(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw std::invalid_argument(fmt::format("{}: cannot read the file", path));
  } catch (const YAML::ParserException& e) {
    throw std::invalid_argument(fmt::format("{}:{}:{}: malformed YAML: {}", path, e.mark.line + 1,
                                            e.mark.column + 1, e.msg));
  }
}

const char* to_string(ModeSpec::Kind kind) {
  switch (kind) {
    case ModeSpec::Kind::kContinuous:
      return "continuous";
    case ModeSpec::Kind::kSingleStep:
      return "single_step";
    case ModeSpec::Kind::kDeactivated:
      return "deactivated";
  }
  return "?";
}

std::string ModeSpec::describe() const {
  switch (kind) {
    case Kind::kContinuous:
      return fmt::format("continuous({})", format_duration(cycle));
    case Kind::kSingleStep:
      return fmt::format("single_step({})", trigger.empty() ? "default" : trigger);
    case Kind::kDeactivated:
      return "deactivated";
  }
  return "?";
}

ModeSpec ModeSpec::parse_text(const std::string& text) {
  const auto colon = text.find(':');
  const auto head = text.substr(0, colon);
  const auto tail = colon == std::string::npos ? std::string() : text.substr(colon + 1);
  ModeSpec m;
  if (head == "continuous") {
    if (tail.empty()) {
      throw std::invalid_argument("mode 'continuous' needs a cycle, e.g. 'continuous:33ms'");
    }
    m.kind = Kind::kContinuous;
    m.cycle = parse_duration(tail);
    if (m.cycle.count() <= 0) throw std::invalid_argument("a continuous cycle must be positive");
  } else if (head == "single_step") {
    m.kind = Kind::kSingleStep;
    if (!tail.empty()) {
      m.trigger = (tail == "command" || tail == "module" || tail.starts_with("input:"))
                      ? tail
                      : "input:" + tail;
    }
  } else if (head == "deactivated" && tail.empty()) {
    m.kind = Kind::kDeactivated;
  } else {
    throw std::invalid_argument(fmt::format(
        "mode '{}': expected continuous:<cycle>, single_step[:<trigger>] or deactivated", text));
  }
  return m;
}

ModeSpec ModeSpec::parse(const YAML::Node& node) {
  if (node.IsScalar()) return parse_text(node.Scalar());
  if (node.IsMap() && node.size() == 1) {
    const auto key = node.begin()->first.as<std::string>();
    const auto value = node.begin()->second;
    if (key == "continuous" && value.IsScalar()) return parse_text("continuous:" + value.Scalar());
    if (key == "single_step") {
      if (value.IsNull()) return parse_text("single_step");
      if (value.IsMap() && value["trigger"] && value.size() == 1) {
        return parse_text("single_step:" + value["trigger"].as<std::string>());
      }
    }
  }
  throw std::invalid_argument(
      "expected single_step, deactivated, {continuous: <cycle>} or {single_step: {trigger: X}}");
}

const char* to_string(KernelErrorPolicy::Action action) {
  switch (action) {
    case KernelErrorPolicy::Action::kContinue:
      return "continue";
    case KernelErrorPolicy::Action::kDeactivate:
      return "deactivate";
    case KernelErrorPolicy::Action::kRestart:
      return "restart";
  }
  return "?";
}

KernelErrorPolicy KernelErrorPolicy::parse(const YAML::Node& node) {
  KernelErrorPolicy p;
  const auto action = [](const std::string& text) {
    for (auto a : {Action::kContinue, Action::kDeactivate, Action::kRestart}) {
      if (text == to_string(a)) return a;
    }
    throw std::invalid_argument(
        fmt::format("unknown action '{}' (allowed: continue, deactivate, restart)", text));
  };
  if (node.IsScalar()) {
    p.action = action(node.as<std::string>());
    return p;
  }
  if (!node.IsMap()) {
    throw std::invalid_argument("expected continue, deactivate, restart or {action: A, after: N}");
  }
  for (const auto& kv : node) {
    const auto key = kv.first.as<std::string>();
    if (key == "action") {
      p.action = action(kv.second.as<std::string>());
    } else if (key == "after") {
      p.after = kv.second.as<int>();
      if (p.after < 1) {
        throw std::invalid_argument(fmt::format(
            "after: {} must be at least 1 (the number of failures in a row to act on)", p.after));
      }
    } else {
      throw std::invalid_argument(fmt::format("unknown key '{}' (allowed: action, after)", key));
    }
  }
  return p;
}

ModuleSpec ModuleSpec::from_yaml(const YAML::Node& node, const std::string& file) {
  if (!node || !node.IsMap()) fail(file, "a module must be a map with name and kernels");
  check_yaml_keys(node, file, "module",
                  {"name", "host", "domain", "kernels", "mode", "stub", "network", "restart",
                   "debug", "watchdog", "standby", "on_kernel_error", "plugins"});
  ModuleSpec m;
  m.where = yaml_where(file, node);
  m.name = scalar(node["name"], m.where, "module name");
  if (!is_identifier(m.name)) {
    fail(m.where, fmt::format("module name '{}' must be an identifier", m.name));
  }
  if (node["host"]) m.host = scalar(node["host"], file, "host");
  if (node["domain"]) m.domain = node["domain"].as<int>();
  const auto kernels = node["kernels"];
  if (!kernels || !kernels.IsSequence() || kernels.size() == 0) {
    fail(m.where, fmt::format("module '{}': kernels must be a non-empty list", m.name));
  }
  std::set<std::string> names;
  for (std::size_t i = 0; i < kernels.size(); ++i) {
    auto k = parse_kernel(kernels[i], file, i);
    if (!names.insert(k.name).second) {
      fail(k.where, fmt::format("module '{}': duplicate kernel name '{}'; kernel names are unique "
                                "within a system",
                                m.name, k.name));
    }
    m.kernels.push_back(std::move(k));
  }
  if (node["mode"]) {
    try {
      m.mode = ModeSpec::parse(node["mode"]);
    } catch (const std::invalid_argument& e) {
      fail(yaml_where(file, node["mode"]), std::string("mode: ") + e.what());
    }
  }
  if (node["stub"]) m.stub = node["stub"].as<bool>();
  if (node["watchdog"]) {
    try {
      m.watchdog = std::chrono::duration_cast<std::chrono::milliseconds>(
          parse_duration(node["watchdog"].as<std::string>()));
    } catch (const std::exception& e) {
      fail(yaml_where(file, node["watchdog"]), std::string("watchdog: ") + e.what());
    }
    if (m.watchdog.count() <= 0) fail(yaml_where(file, node["watchdog"]), "watchdog must be > 0");
  }
  if (node["on_kernel_error"]) {
    try {
      m.on_kernel_error = KernelErrorPolicy::parse(node["on_kernel_error"]);
    } catch (const std::exception& e) {
      fail(yaml_where(file, node["on_kernel_error"]), std::string("on_kernel_error: ") + e.what());
    }
  }
  m.plugins = plugins_of(node, file);
  try {
    m.network = NetworkConfig::from_yaml(node["network"]);
  } catch (const std::invalid_argument& e) {
    fail(yaml_where(file, node["network"]), e.what());
  }
  return m;
}

ModuleSpec ModuleSpec::load(const std::string& path, const std::string& module) {
  const auto root = load_yaml_file(path);
  if (root.IsMap() && root["modules"]) {
    const auto modules = root["modules"];
    std::vector<std::string> names;
    for (const auto& m : modules) {
      if (m["name"] && m["name"].IsScalar()) names.push_back(m["name"].Scalar());
      if (m["name"] && m["name"].IsScalar() && (module.empty() || m["name"].Scalar() == module)) {
        if (module.empty() && modules.size() > 1) break;
        auto spec = from_yaml(m, path);
        if (!spec.domain && root["domain"]) spec.domain = root["domain"].as<int>();
        if (!m["network"]) spec.network = NetworkConfig::for_host(root, spec.host);
        if (const auto keystore = security_files::system_keystore(root, path); !keystore.empty()) {
          spec.network.security =
              ParticipantSecurity{keystore, security_files::module_identity(spec.name)};
        }
        const auto system_plugins = plugins_of(root, path);
        spec.plugins.insert(spec.plugins.begin(), system_plugins.begin(), system_plugins.end());
        if (root["lease"]) {
          spec.lease = std::chrono::duration_cast<std::chrono::milliseconds>(
              parse_duration(root["lease"].as<std::string>()));
        }
        for (const auto& other : modules) {
          if (other["name"] && other["name"].IsScalar()) {
            spec.system_modules.push_back(other["name"].Scalar());
          }
        }
        // The `coordinator:` section runs as a module of this name (SystemSpec).
        if (root["coordinator"]) spec.system_modules.push_back("coordinator");
        return spec;
      }
    }
    throw std::invalid_argument(fmt::format("{}: {} (modules: {})", path,
                                            module.empty()
                                                ? "the system has several modules; name one"
                                                : "no module named '" + module + "'",
                                            fmt::join(names, ", ")));
  }
  return from_yaml(root, path);
}

std::vector<std::string> ModuleSpec::plugins_of(const YAML::Node& root, const std::string& file) {
  const auto node = root["plugins"];
  if (!node) return {};
  const auto where = yaml_where(file, node);
  std::vector<std::string> texts;
  if (node.IsScalar()) {
    texts.push_back(node.Scalar());
  } else if (node.IsSequence()) {
    for (const auto& p : node) {
      if (!p.IsScalar()) fail(yaml_where(file, p), "plugins: each entry is a path");
      texts.push_back(p.Scalar());
    }
  } else {
    fail(where, "plugins: expected a path or a list of paths (plugin files or folders of them)");
  }
  const auto base = std::filesystem::absolute(file).parent_path();
  std::vector<std::string> out;
  for (const auto& text : texts) {
    const auto path = (base / text).lexically_normal();  // an absolute `text` stays as it is
    if (!std::filesystem::exists(path)) {
      fail(where, fmt::format("plugins: '{}' does not exist (a plugin liboscar_kernel_<type>.so "
                              "or a folder of them; relative paths start at the file's folder)",
                              path.string()));
    }
    out.push_back(path.string());
  }
  return out;
}

const KernelSpec* ModuleSpec::find_kernel(const std::string& kernel_name) const {
  for (const auto& k : kernels) {
    if (k.name == kernel_name) return &k;
  }
  return nullptr;
}

void ModuleSpec::restore(const YAML::Node& state) {
  if (!state.IsMap()) throw std::invalid_argument("restore: expected a map of kernel: state");
  for (const auto& kv : state) {
    const auto kernel = kv.first.as<std::string>();
    auto it = std::find_if(kernels.begin(), kernels.end(),
                           [&](const KernelSpec& k) { return k.name == kernel; });
    if (it == kernels.end()) {
      throw std::invalid_argument(
          fmt::format("restore: module '{}' has no kernel '{}'", name, kernel));
    }
    const auto what = "restore: kernel '" + kernel + "'";
    check_yaml_keys(kv.second, "<restore>", what, {"mode", "stub", "params", "inputs"});
    if (const auto m = kv.second["mode"]) it->mode = ModeSpec::parse_text(m.as<std::string>());
    if (const auto st = kv.second["stub"]) it->stub = st.as<bool>();
    if (const auto p = kv.second["params"]) {
      if (!it->params || !it->params.IsMap()) it->params = YAML::Node(YAML::NodeType::Map);
      for (const auto& param : p) it->params[param.first.as<std::string>()] = param.second;
    }
    if (const auto in = kv.second["inputs"]) {
      for (const auto& wire : in)
        it->inputs[wire.first.as<std::string>()].source = wire.second.as<std::string>();
    }
  }
}

ModeSpec ModuleSpec::effective_mode(const KernelSpec& kernel) const {
  if (kernel.mode) return *kernel.mode;
  if (mode.kind == ModeSpec::Kind::kContinuous && &kernel != &kernels.front()) {
    return ModeSpec{ModeSpec::Kind::kSingleStep, {}, "module"};
  }
  return mode;
}

}  // namespace oscar
