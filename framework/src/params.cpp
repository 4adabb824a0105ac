#include "oscar/params.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "oscar/time.hpp"

namespace oscar {
namespace {

std::string scalar_text(const YAML::Node& node) {
  return node.IsScalar() ? node.Scalar() : YAML::Dump(node);
}

std::invalid_argument type_error(const std::string& owner, const ParamField& f,
                                 const YAML::Node& node) {
  return std::invalid_argument(fmt::format("{}: parameter '{}' expects a {}, got '{}'", owner,
                                           f.name, f.type, scalar_text(node)));
}

void check_range(const std::string& owner, const ParamField& f, double v, std::string_view text) {
  if ((f.min && v < *f.min) || (f.max && v > *f.max)) {
    throw std::invalid_argument(fmt::format(
        "{}: parameter '{}' = {} is outside its range [{}, {}]", owner, f.name, text,
        f.min ? fmt::format("{}", *f.min) : "-inf", f.max ? fmt::format("{}", *f.max) : "inf"));
  }
}

ParamField blank(std::string name, std::string type, std::string help) {
  ParamField f;
  f.name = std::move(name);
  f.type = std::move(type);
  f.help = std::move(help);
  return f;
}

}  // namespace

ParamField& ParamSpec::add(ParamField f) {
  if (find(f.name)) {
    throw std::logic_error(fmt::format("{}: parameter '{}' is described twice", owner_, f.name));
  }
  fields_.push_back(std::move(f));
  return fields_.back();
}

const ParamField* ParamSpec::find(std::string_view name) const {
  for (const auto& f : fields_) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

std::string ParamSpec::known_names() const {
  std::string names;
  for (const auto& f : fields_) names += (names.empty() ? "" : ", ") + f.name;
  return names.empty() ? "(none)" : names;
}

ParamField& ParamSpec::field(std::string name, bool& value, std::string help) {
  auto f = blank(std::move(name), "bool", std::move(help));
  f.get = [&value] { return value ? std::string("true") : std::string("false"); };
  auto& added = add(std::move(f));
  added.set = [this, &value, &added](const YAML::Node& n) {
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) throw type_error(owner_, added, n);
    value = v;
  };
  return added;
}

ParamField& ParamSpec::field(std::string name, std::int64_t& value, std::string help) {
  auto f = blank(std::move(name), "int", std::move(help));
  f.get = [&value] { return std::to_string(value); };
  auto& added = add(std::move(f));
  added.set = [this, &value, &added](const YAML::Node& n) {
    long long v = 0;
    if (!n.IsScalar() || !YAML::convert<long long>::decode(n, v)) {
      throw type_error(owner_, added, n);
    }
    check_range(owner_, added, static_cast<double>(v), n.Scalar());
    value = v;
  };
  return added;
}

ParamField& ParamSpec::field(std::string name, int& value, std::string help) {
  auto f = blank(std::move(name), "int", std::move(help));
  f.get = [&value] { return std::to_string(value); };
  auto& added = add(std::move(f));
  added.set = [this, &value, &added](const YAML::Node& n) {
    int v = 0;
    if (!n.IsScalar() || !YAML::convert<int>::decode(n, v)) throw type_error(owner_, added, n);
    check_range(owner_, added, v, n.Scalar());
    value = v;
  };
  return added;
}

ParamField& ParamSpec::field(std::string name, double& value, std::string help) {
  auto f = blank(std::move(name), "double", std::move(help));
  f.get = [&value] { return fmt::format("{}", value); };
  auto& added = add(std::move(f));
  added.set = [this, &value, &added](const YAML::Node& n) {
    double v = 0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v)) {
      throw type_error(owner_, added, n);
    }
    check_range(owner_, added, v, n.Scalar());
    value = v;
  };
  return added;
}

ParamField& ParamSpec::field(std::string name, std::string& value, std::string help) {
  auto f = blank(std::move(name), "string", std::move(help));
  f.get = [&value] { return value; };
  auto& added = add(std::move(f));
  added.set = [this, &value, &added](const YAML::Node& n) {
    if (!n.IsScalar()) throw type_error(owner_, added, n);
    if (!added.choices.empty() &&
        std::find(added.choices.begin(), added.choices.end(), n.Scalar()) == added.choices.end()) {
      throw std::invalid_argument(fmt::format("{}: parameter '{}' = '{}' is not one of: {}", owner_,
                                              added.name, n.Scalar(),
                                              fmt::join(added.choices, ", ")));
    }
    value = n.Scalar();
  };
  return added;
}

ParamField& ParamSpec::field(std::string name, std::chrono::nanoseconds& value, std::string help) {
  auto f = blank(std::move(name), "duration", std::move(help));
  f.get = [&value] { return format_duration(value); };
  auto& added = add(std::move(f));
  added.set = [this, &value, &added](const YAML::Node& n) {
    if (!n.IsScalar()) throw type_error(owner_, added, n);
    std::chrono::nanoseconds v{};
    try {
      v = parse_duration(n.Scalar());
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(
          fmt::format("{}: parameter '{}': {}", owner_, added.name, e.what()));
    }
    check_range(owner_, added, std::chrono::duration<double>(v).count(), n.Scalar());
    value = v;
  };
  return added;
}

void ParamSpec::set(std::string_view name, const YAML::Node& value) {
  const auto* f = find(name);
  if (!f) {
    throw std::invalid_argument(
        fmt::format("{} has no parameter '{}'; its parameters: {}", owner_, name, known_names()));
  }
  f->set(value);
}

void ParamSpec::set_text(std::string_view name, std::string_view text) {
  YAML::Node node;
  try {
    node = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(fmt::format("{}: value '{}' for parameter '{}' is not YAML: {}",
                                            owner_, text, name, e.msg));
  }
  if (text.empty()) node = YAML::Node(std::string());
  set(name, node);
}

void ParamSpec::set_all(const YAML::Node& map) {
  if (!map || map.IsNull()) return;
  if (!map.IsMap()) {
    throw std::invalid_argument(fmt::format("{}: params must be a map of name: value", owner_));
  }
  for (const auto& kv : map) set(kv.first.Scalar(), kv.second);
}

std::string ParamSpec::to_yaml() const {
  YAML::Emitter out;
  out << YAML::BeginMap;
  for (const auto& f : fields_) out << YAML::Key << f.name << YAML::Value << f.get();
  out << YAML::EndMap;
  return out.c_str();
}

}  // namespace oscar
