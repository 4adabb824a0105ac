#include "policy_xml.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar::security {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

std::size_t count_of(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (auto at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

// The rule for `expression`, from its expression to its end.
std::string rule_of(const std::string& governance, const std::string& expression) {
  const auto at = governance.find("<topic_expression>" + expression + "</topic_expression>");
  if (at == std::string::npos) return "";
  return governance.substr(at, governance.find("</topic_rule>", at) - at);
}

TEST(Governance, CueProtectionSetsTheCueAndPullRulesAndControlTopicsStayProtected) {
  using P = SecuritySpec::CueProtection;
  const auto none = governance_xml(P::kNone);
  const auto sign = governance_xml(P::kSign);
  const auto encrypt = governance_xml(P::kEncrypt);
  for (const auto* topics : {"oscar/cue/*", "oscar/pull/*/request", "oscar/pull/*/reply"}) {
    SCOPED_TRACE(topics);
    EXPECT_THAT(rule_of(none, topics), HasSubstr("<metadata_protection_kind>NONE</metadata_"
                                                 "protection_kind>\n          <data_protection_"
                                                 "kind>NONE</"));
    // Sign protects the submessage with the sample in it (data SIGN alone fails in Fast DDS 2.9).
    EXPECT_THAT(rule_of(sign, topics), HasSubstr("<metadata_protection_kind>SIGN</metadata_"
                                                 "protection_kind>\n          <data_protection_"
                                                 "kind>NONE</"));
    EXPECT_THAT(rule_of(encrypt, topics), HasSubstr("<metadata_protection_kind>ENCRYPT</metadata_"
                                                    "protection_kind>\n          <data_protection_"
                                                    "kind>ENCRYPT</"));
  }
  for (const auto& governance : {none, sign, encrypt}) {
    EXPECT_THAT(rule_of(governance, "*"), HasSubstr("<metadata_protection_kind>SIGN</metadata_"
                                                    "protection_kind>\n          <data_protection_"
                                                    "kind>ENCRYPT</"));
    EXPECT_THAT(governance, HasSubstr("<allow_unauthenticated_participants>false</"));
    EXPECT_THAT(governance, HasSubstr("<enable_join_access_control>true</"));
    // Announcements are not transformed (half a secured boot's CPU), but every topic is still
    // announced only on the secure discovery endpoints, to authenticated participants alone.
    EXPECT_THAT(governance, HasSubstr("<discovery_protection_kind>NONE</"));
    EXPECT_THAT(governance, HasSubstr("<liveliness_protection_kind>NONE</"));
    EXPECT_THAT(governance, Not(HasSubstr("<enable_discovery_protection>false</")));
    EXPECT_EQ(count_of(governance, "<enable_discovery_protection>true</"),
              count_of(governance, "<topic_rule>"));
    EXPECT_EQ(count_of(governance, "<enable_write_access_control>true</"),
              count_of(governance, "<topic_rule>"));
    // The catch-all comes last: the first matching rule applies.
    EXPECT_GT(governance.find("<topic_expression>*</"), governance.find("oscar/pull/*/reply"));
  }
}

TEST(Permissions, NameTheSubjectAndDenyWhatIsNotAllowed) {
  const IdentityPolicy viewer{"module.viewer", {"oscar/cue/view/*"}, {"*"}};
  const auto xml = permissions_xml(viewer, "CN=module.viewer,O=OSCAR", "2026-01-01T00:00:00",
                                   "2028-01-01T00:00:00");
  EXPECT_THAT(xml, HasSubstr("<grant name=\"module.viewer\">\n      <subject_name>CN=module."
                             "viewer,O=OSCAR</subject_name>"));
  EXPECT_THAT(xml, HasSubstr("<not_before>2026-01-01T00:00:00</not_before>"));
  EXPECT_THAT(xml, HasSubstr("<publish>\n          <topics>\n            <topic>oscar/cue/view/*"
                             "</topic>"));
  EXPECT_THAT(xml, HasSubstr("<default>DENY</default>"));
  const IdentityPolicy reader{"operator", {}, {"*"}};
  EXPECT_THAT(permissions_xml(reader, "CN=operator,O=OSCAR", "a", "b"),
              ::testing::Not(HasSubstr("<publish>")));
}

}  // namespace
}  // namespace oscar::security
