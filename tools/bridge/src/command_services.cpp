#include "command_services.hpp"

#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "json_schemas.hpp"

namespace oscar::bridge {
using json = nlohmann::ordered_json;

namespace {

bool is_64_bit_integer(const std::string& primitive) {
  return primitive == "long long" || primitive == "unsigned long long";
}

json primitive_schema(const std::string& name) {
  if (name == "boolean") return {{"type", "boolean"}};
  if (name == "float" || name == "double") return {{"type", "number"}};
  if (is_64_bit_integer(name)) {
    // JavaScript numbers hold integers exactly only up to 2^53 (a time in ns since the epoch is
    // larger), so a string of digits is taken too.
    return {{"type", json::array({"integer", "string"})},
            {"pattern", name == "long long" ? "^-?[0-9]+$" : "^[0-9]+$"}};
  }
  return {{"type", "integer"}};
}

json type_schema(const inspect::IdlTypes& types, const inspect::IdlType& t, int depth);

json struct_schema(const inspect::IdlTypes& types, const std::string& name, int depth) {
  // IDL structs cannot contain themselves but a reader's bug could: stop rather than recurse.
  if (depth > 32) throw std::invalid_argument("IDL type '" + name + "' nests too deeply");
  const auto* members = types.members(name);
  if (!members) throw std::invalid_argument("no IDL text here declares the struct '" + name + "'");
  json properties = json::object();
  for (const auto& m : *members) properties[m.name] = type_schema(types, m.type, depth + 1);
  return {{"type", "object"},
          {"description", name},
          {"properties", properties},
          {"additionalProperties", false}};
}

json type_schema(const inspect::IdlTypes& types, const inspect::IdlType& t, int depth) {
  using Kind = inspect::IdlType::Kind;
  switch (t.kind) {
    case Kind::kPrimitive:
      return primitive_schema(t.name);
    case Kind::kString:
      return {{"type", "string"}};
    case Kind::kSequence:
    case Kind::kArray: {
      json s = {{"type", "array"}, {"items", type_schema(types, *t.element, depth + 1)}};
      if (t.kind == Kind::kArray) {
        s["minItems"] = t.array_size;
        s["maxItems"] = t.array_size;
      }
      return s;
    }
    case Kind::kEnum:
    case Kind::kStruct:
      if (const auto* names = types.enumerators(t.name)) {
        return {{"type", "string"}, {"enum", *names}, {"description", t.name}};
      }
      return struct_schema(types, t.name, depth);
  }
  return json::object();
}

// The YAML node IdlTypes::from_yaml() reads for a JSON value: objects as maps, arrays as
// sequences, everything else as a scalar of its text (numbers keep their digits exactly).
YAML::Node to_yaml(const json& value) {
  if (value.is_object()) {
    YAML::Node map(YAML::NodeType::Map);
    for (const auto& [key, member] : value.items()) map[key] = to_yaml(member);
    return map;
  }
  if (value.is_array()) {
    YAML::Node list(YAML::NodeType::Sequence);
    for (const auto& item : value) list.push_back(to_yaml(item));
    return list;
  }
  if (value.is_null()) return YAML::Node(YAML::NodeType::Null);
  if (value.is_string()) return YAML::Node(value.get<std::string>());
  return YAML::Node(value.dump());
}

// A JSON string where the IDL wants a number or a boolean is taken only for 64-bit integers;
// a number or boolean where it wants a string or enum is refused (YAML would take either).
void check_json_types(const inspect::IdlTypes& types, const inspect::IdlType& t, const json& v,
                      const std::string& path) {
  using Kind = inspect::IdlType::Kind;
  const auto fail = [&](const std::string& rule) {
    throw std::invalid_argument(path.empty() ? rule : fmt::format("{}: {}", path, rule));
  };
  if (v.is_null()) return;  // the IDL default
  switch (t.kind) {
    case Kind::kPrimitive:
      if (t.name == "boolean" && !v.is_boolean()) fail(fmt::format("{} is no boolean", v.dump()));
      if (t.name != "boolean" && !v.is_number() && !(v.is_string() && is_64_bit_integer(t.name)))
        fail(fmt::format("{} is no number ({})", v.dump(), t.name));
      return;
    case Kind::kString:
      if (!v.is_string()) fail(fmt::format("{} is no string", v.dump()));
      return;
    case Kind::kSequence:
    case Kind::kArray:
      if (!v.is_array()) fail(fmt::format("{} is no array", v.dump()));
      for (std::size_t i = 0; i < v.size(); ++i) {
        check_json_types(types, *t.element, v[i], fmt::format("{}[{}]", path, i));
      }
      return;
    case Kind::kEnum:
    case Kind::kStruct:
      if (types.enumerators(t.name)) {
        if (!v.is_string()) fail(fmt::format("{} is no enumerator name of {}", v.dump(), t.name));
        return;
      }
      if (!v.is_object()) fail(fmt::format("{} is no object ({})", v.dump(), t.name));
      if (const auto* members = types.members(t.name)) {
        for (const auto& m : *members) {
          if (const auto it = v.find(m.name); it != v.end()) {
            check_json_types(types, m.type, *it,
                             path.empty() ? m.name : fmt::format("{}.{}", path, m.name));
          }
        }
      }
      return;
  }
}

}  // namespace

std::string KernelCommand::service_name() const {
  return fmt::format("oscar/{}/{}/{}", module, kernel, name);
}

std::vector<KernelCommand> running_commands(const SystemState& state) {
  std::vector<KernelCommand> out;
  for (const auto& m : state.modules()) {
    if (m.status() != "running") continue;
    for (const auto& k : m.state().kernels()) {
      for (const auto& c : k.commands()) out.push_back({m.name(), k.name(), c.name(), c.type()});
    }
  }
  return out;
}

std::string request_json_schema(const inspect::IdlTypes& types, const std::string& type) {
  auto schema = struct_schema(types, type, 0);
  schema["title"] = type;
  return schema.dump();
}

std::vector<std::uint8_t> request_cdr(const inspect::IdlTypes& types, const std::string& type,
                                      std::string_view payload) {
  const auto value = json::parse(payload, nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded() || !value.is_object()) {
    throw std::invalid_argument(
        fmt::format("the request must be a JSON object of the members of {}", type));
  }
  inspect::IdlType request;
  request.kind = inspect::IdlType::Kind::kStruct;
  request.name = type;
  check_json_types(types, request, value, "");
  return types.from_yaml(type, to_yaml(value));
}

std::string command_response_json(const KernelCommand& command, const std::string& answer) {
  return json{{"module", command.module},
              {"kernel", command.kernel},
              {"command", command.name},
              {"answer", answer}}
      .dump();
}

CommandServices::CommandServices(const inspect::IdlTypes& types, std::uint32_t first_id)
    : types_(types), next_id_(first_id) {}

ServiceInfo CommandServices::info(std::uint32_t id, const KernelCommand& command) const {
  return {.id = id,
          .name = command.service_name(),
          .type = command.request_type,
          .request_schema_name = command.request_type,
          .request_schema = request_json_schema(types_, command.request_type),
          .response_schema_name = "oscar.CommandResponse",
          .response_schema = json_schema("oscar.CommandResponse")};
}

CommandServices::Change CommandServices::update(const std::vector<KernelCommand>& commands) {
  Change change;
  std::map<std::uint32_t, ServiceInfo> now;
  for (const auto& c : commands) {
    if (!types_.has(c.request_type)) {
      if (!reported_unknown_[c.request_type]) {
        reported_unknown_[c.request_type] = true;
        change.unknown_types.push_back(c);
      }
      continue;
    }
    const auto key = c.service_name() + "|" + c.request_type;
    auto [it, fresh] = id_of_.try_emplace(key, next_id_);
    if (fresh) ++next_id_;
    const auto id = it->second;
    known_[id] = c;
    if (now.count(id)) continue;  // listed twice
    if (const auto was = offered_.find(id); was != offered_.end()) {
      now.emplace(id, was->second);
    } else {
      now.emplace(id, info(id, c));
      change.added.push_back(now.at(id));
    }
  }
  for (const auto& [id, service] : offered_) {
    if (!now.count(id)) change.removed.push_back(id);
  }
  offered_ = std::move(now);
  return change;
}

std::vector<ServiceInfo> CommandServices::services() const {
  std::vector<ServiceInfo> out;
  for (const auto& [id, service] : offered_) out.push_back(service);
  return out;
}

const KernelCommand* CommandServices::offered(std::uint32_t id) const {
  return offered_.count(id) ? &known_.at(id) : nullptr;
}

const KernelCommand* CommandServices::ever(std::uint32_t id) const {
  const auto it = known_.find(id);
  return it == known_.end() ? nullptr : &it->second;
}

}  // namespace oscar::bridge
