#pragma once
// A JSON value checked against a JSON schema, as far as the bridge's schemas use it: type,
// required, properties, items, maxItems, minimum and const alternatives (oneOf). Returns what does
// not conform ("" if all does), naming the path.
#include <string>

#include <nlohmann/json.hpp>

namespace oscar::bridge::test {

inline std::string schema_mismatch(const nlohmann::json& schema, const nlohmann::json& value,
                                   const std::string& path = "$") {
  if (schema.contains("oneOf")) {
    for (const auto& alternative : schema["oneOf"]) {
      if (alternative.contains("const") && alternative["const"] == value) return "";
    }
    return path + ": none of its alternatives";
  }
  const auto type = schema.value("type", std::string());
  const bool ok =
      type.empty() || (type == "object" && value.is_object()) ||
      (type == "array" && value.is_array()) || (type == "string" && value.is_string()) ||
      (type == "integer" && value.is_number_integer()) || (type == "number" && value.is_number()) ||
      (type == "boolean" && value.is_boolean());
  if (!ok) return path + ": expected " + type + ", got " + value.dump().substr(0, 80);
  if (schema.contains("minimum") && value.is_number() && value.get<double>() < schema["minimum"]) {
    return path + ": below its minimum";
  }
  if (type == "object") {
    const auto required = schema.value("required", nlohmann::json::array());
    for (const auto& name : required) {
      if (!value.contains(name.get<std::string>())) return path + ": lacks " + name.dump();
    }
    const auto properties = schema.value("properties", nlohmann::json::object());
    for (const auto& [name, sub] : properties.items()) {
      if (!value.contains(name)) continue;
      if (auto m = schema_mismatch(sub, value[name], path + "." + name); !m.empty()) return m;
    }
  }
  if (type == "array" && schema.contains("maxItems") && value.size() > schema["maxItems"]) {
    return path + ": more than " + schema["maxItems"].dump() + " items";
  }
  if (type == "array" && schema.contains("items")) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      const auto m =
          schema_mismatch(schema["items"], value[i], path + "[" + std::to_string(i) + "]");
      if (!m.empty()) return m;
    }
  }
  return "";
}

// The first field of `value` that `schema` does not declare (a property it does not list, an
// item of an array whose items it does not describe), as a path; "" if there is none. The
// schemas of Foxglove's types declare all the bridge sends, so Foxglove's panels get no field
// the tests did not hold to Foxglove's published schema (tests/foxglove/schema_checks.js).
inline std::string undeclared_field(const nlohmann::json& schema, const nlohmann::json& value,
                                    const std::string& path = "$") {
  if (value.is_array()) {
    if (!value.empty() && !schema.contains("items")) return path + "[0]";
    for (std::size_t i = 0; i < value.size(); ++i) {
      const auto u =
          undeclared_field(schema["items"], value[i], path + "[" + std::to_string(i) + "]");
      if (!u.empty()) return u;
    }
  } else if (value.is_object()) {
    const auto properties = schema.value("properties", nlohmann::json::object());
    for (const auto& [name, sub] : value.items()) {
      if (!properties.contains(name)) return path + "." + name;
      if (auto u = undeclared_field(properties[name], sub, path + "." + name); !u.empty()) return u;
    }
  }
  return "";
}

}  // namespace oscar::bridge::test
