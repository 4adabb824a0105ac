#include "policy_xml.hpp"

#include <fmt/format.h>

#include "oscar/topics.hpp"

namespace oscar::security {
namespace {

// Every domain OSCAR may run on: boot --domain, $OSCAR_DOMAIN and the tests move a system off the
// domain its file names, and its keystore must go along.
constexpr const char* kAllDomains =
    "<domains><id_range><min>0</min><max>232</max></id_range></domains>";

std::string escaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The protection of a cue topic's submessages (metadata) and of its samples (data). "sign"
// signs the whole DATA submessage, sample included, and leaves the sample itself alone: Fast DDS
// 2.9 cannot decode a sample signed on its own (data SIGN) when its serialized form ends in
// padding (secure_participants_test saw every sample dropped; fixed upstream only in 2026).
struct Protection {
  const char* metadata;
  const char* data;
};

Protection protection(SecuritySpec::CueProtection p) {
  switch (p) {
    case SecuritySpec::CueProtection::kNone:
      return {"NONE", "NONE"};
    case SecuritySpec::CueProtection::kSign:
      return {"SIGN", "NONE"};
    case SecuritySpec::CueProtection::kEncrypt:
      return {"ENCRYPT", "ENCRYPT"};
  }
  return {"ENCRYPT", "ENCRYPT"};
}

std::string topic_rule(const std::string& expression, Protection p) {
  return fmt::format(
      "        <topic_rule>\n"
      "          <topic_expression>{}</topic_expression>\n"
      "          <enable_discovery_protection>true</enable_discovery_protection>\n"
      "          <enable_liveliness_protection>true</enable_liveliness_protection>\n"
      "          <enable_read_access_control>false</enable_read_access_control>\n"
      "          <enable_write_access_control>true</enable_write_access_control>\n"
      "          <metadata_protection_kind>{}</metadata_protection_kind>\n"
      "          <data_protection_kind>{}</data_protection_kind>\n"
      "        </topic_rule>\n",
      escaped(expression), p.metadata, p.data);
}

std::string topic_list(const char* element, const std::vector<std::string>& topics) {
  if (topics.empty()) return "";
  std::string out = fmt::format("        <{}>\n          <topics>\n", element);
  for (const auto& t : topics) out += fmt::format("            <topic>{}</topic>\n", escaped(t));
  return out + fmt::format("          </topics>\n        </{}>\n", element);
}

}  // namespace

std::string governance_xml(SecuritySpec::CueProtection cue) {
  // The first rule whose expression matches a topic applies (Fast DDS and the spec): cue and pull
  // topics (which carry cues too) first, then every other topic.
  //
  // Discovery and liveliness messages are not transformed (kind NONE): every topic rule keeps
  // enable_discovery_protection, so endpoints are still announced only on the secure discovery
  // endpoints, which match authenticated participants alone. Signing or encrypting those
  // announcements, once per receiver, was half the CPU of a secured 20-module boot (docs/
  // benchmarks.md) and kept only topic names and QoS from whoever captures the network; the
  // samples of every control topic stay signed and encrypted (docs/security.md, "Governance").
  return fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<!-- Written by `oscar security init` from the system file: do not edit (it is signed). "
      "-->\n"
      "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
      "xsi:noNamespaceSchemaLocation=\"omg_shared_ca_governance.xsd\">\n"
      "  <domain_access_rules>\n"
      "    <domain_rule>\n"
      "      {}\n"
      "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
      "      <enable_join_access_control>true</enable_join_access_control>\n"
      "      <discovery_protection_kind>NONE</discovery_protection_kind>\n"
      "      <liveliness_protection_kind>NONE</liveliness_protection_kind>\n"
      "      <rtps_protection_kind>NONE</rtps_protection_kind>\n"
      "      <topic_access_rules>\n"
      "{}{}{}{}"
      "      </topic_access_rules>\n"
      "    </domain_rule>\n"
      "  </domain_access_rules>\n"
      "</dds>\n",
      kAllDomains, topic_rule(std::string(topics::kCuePrefix) + "*", protection(cue)),
      topic_rule(topics::pull_request("*").name, protection(cue)),
      topic_rule(topics::pull_reply("*").name, protection(cue)),
      topic_rule("*", {"SIGN", "ENCRYPT"}));
}

std::string permissions_xml(const IdentityPolicy& identity, const std::string& subject_rfc2253,
                            const std::string& not_before, const std::string& not_after) {
  return fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<!-- Written by `oscar security init` from the system file: do not edit (it is signed). "
      "-->\n"
      "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
      "xsi:noNamespaceSchemaLocation=\"omg_shared_ca_permissions.xsd\">\n"
      "  <permissions>\n"
      "    <grant name=\"{}\">\n"
      "      <subject_name>{}</subject_name>\n"
      "      <validity>\n"
      "        <not_before>{}</not_before>\n"
      "        <not_after>{}</not_after>\n"
      "      </validity>\n"
      "      <allow_rule>\n"
      "        {}\n"
      "{}{}"
      "      </allow_rule>\n"
      "      <default>DENY</default>\n"
      "    </grant>\n"
      "  </permissions>\n"
      "</dds>\n",
      escaped(identity.name), escaped(subject_rfc2253), not_before, not_after, kAllDomains,
      topic_list("publish", identity.publish), topic_list("subscribe", identity.subscribe));
}

}  // namespace oscar::security
