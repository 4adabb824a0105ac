#include "idl_types.hpp"

#include <set>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <oscar/config.h>
#include <oscar/configPubSubTypes.h>
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/idl_texts.hpp"
#include "oscar/perception_types.hpp"
#include "oscar/plain_cue_types.hpp"

namespace oscar::inspect {
namespace {
using testing::HasSubstr;

IdlTypes oscar_types() {
  IdlTypes types;
  std::set<std::string> seen;
  for (const auto& [name, text] : idl_texts()) {
    if (seen.insert(text).second) types.add(text);
  }
  return types;
}

template <class T>
std::vector<std::uint8_t> bytes_of(const T& cue) {
  return cue_type_info<T>().serialize(&cue);
}

std::vector<std::uint8_t> bytes_of_plain(ConfigCommand& c) {
  ConfigCommandPubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&c)());
  EXPECT_TRUE(type.serialize(&c, &payload));
  return {payload.data, payload.data + payload.length};
}

TEST(IdlTypes, ShowsABoolCueWithItsHeader) {
  Bool b;
  b.header().stamps({1'700'000'000'123'456'789ull, 1'700'000'000'200'000'000ull});
  b.header().source("sig/out");
  b.header().seq(42);
  b.value(true);
  EXPECT_EQ(oscar_types().to_text("oscar::Bool", bytes_of(b), {}),
            "header:\n"
            "  stamps: [1700000000123456789, 1700000000200000000]  # generated "
            "2023-11-14T22:13:20.123456789Z\n"
            "  source: \"sig/out\"\n"
            "  seq: 42\n"
            "value: true");
}

TEST(IdlTypes, ShowsAPlainCueWithItsFixedHeaderAndTheSourceAsText) {
  PlainBool b;
  append_stamp(b.header(), 1'700'000'000'123'456'789);
  set_source(b.header(), "sig/out");
  b.header().seq(42);
  b.value(true);
  EXPECT_EQ(oscar_types().to_text("oscar::PlainBool", bytes_of(b), {}),
            "header:\n"
            "  stamps: [1700000000123456789, 0, 0, 0, 0, 0, 0, 0]  # generated "
            "2023-11-14T22:13:20.123456789Z\n"
            "  stamp_count: 1\n"
            "  source: \"sig/out\"\n"
            "  seq: 42\n"
            "value: true");
}

TEST(IdlTypes, ShowsSequencesOfStructsAsListsAndCutsLongOnes) {
  LineSeg3DSeq l;
  l.header().seq(1);
  l.lines().resize(3);
  l.lines()[1].sx(1.5);
  l.lines()[2].ez(-2);
  const auto text = oscar_types().to_text("oscar::LineSeg3DSeq", bytes_of(l), {.max_items = 2});
  EXPECT_THAT(text, HasSubstr("lines:\n"
                              "  - sx: 0\n"
                              "    sy: 0\n"
                              "    sz: 0\n"
                              "    ex: 0\n"
                              "    ey: 0\n"
                              "    ez: 0\n"
                              "  - sx: 1.5\n"));
  EXPECT_THAT(text, HasSubstr("  # ... 3 items"));
  EXPECT_THAT(text, testing::Not(HasSubstr("-2")));
  EXPECT_THAT(text, HasSubstr("  stamps: []\n"));
}

TEST(IdlTypes, ShowsAnImageWithItsSizeAndFirstBytes) {
  GvImage g;
  g.dx(4);
  g.dy(-3);
  g.image({1, 2, 3, 4, 5, 255});
  const auto text = oscar_types().to_text("oscar::GvImage", bytes_of(g), {.max_items = 4});
  EXPECT_THAT(text, HasSubstr("dx: 4\ndy: -3\nimage: [1, 2, 3, 4, ...]  # 6 items"));
}

TEST(IdlTypes, ShowsEnumsByName) {
  ConfigCommand c;
  c.kind(CMD_REWIRE);
  c.args({"k", "in"});
  const auto text = oscar_types().to_text("oscar::ConfigCommand", bytes_of_plain(c), {});
  EXPECT_THAT(text, HasSubstr("kind: CMD_REWIRE\nargs: [\"k\", \"in\"]"));
}

TEST(IdlTypes, ReportsTruncatedSamplesAndUnknownTypes) {
  Bool b;
  b.header().source("a/b");
  auto bytes = bytes_of(b);
  bytes.resize(10);
  const auto types = oscar_types();
  EXPECT_THAT([&] { types.to_text("oscar::Bool", bytes, {}); },
              testing::ThrowsMessage<std::runtime_error>(HasSubstr("the sample ends early")));
  EXPECT_THAT(
      [&] { types.to_text("oscar::Nope", bytes, {}); },
      testing::ThrowsMessage<std::invalid_argument>(HasSubstr("unknown IDL type 'oscar::Nope'")));
  EXPECT_THAT(
      [&] {
        IdlTypes t;
        t.add("module m { struct S { long a } ; };");
      },
      testing::ThrowsMessage<std::invalid_argument>(HasSubstr("IDL: expected ';', got '}'")));
}

// A module announces its types' IDL over the network (oscar/type_texts.hpp): a text that would
// make decoding recurse without end, or that redeclares a type already known, is refused whole.
TEST(IdlTypes, RefusesRecursionDeepNestingAndRedeclarationsAndKeepsWhatItHad) {
  const auto refused = [](IdlTypes& t, const std::string& text, const std::string& why) {
    EXPECT_THAT([&] { t.add(text); }, testing::ThrowsMessage<std::invalid_argument>(HasSubstr(why)))
        << text;
  };
  IdlTypes t;
  t.add("module acme { struct Leaf { long a; }; struct Arm { Leaf leaf; }; };");
  refused(t, "module evil { struct A { A a; }; };",
          "struct 'evil::A' contains itself (evil::A > evil::A)");
  refused(t,
          "module evil { struct B { long x; }; struct A { sequence<B> b; }; struct B { A a; }; };",
          "recursive types are not supported");
  std::string chain = "module deep { struct S0 { long a; };";
  for (int i = 1; i <= 40; ++i) chain += fmt::format(" struct S{} {{ S{} s; }};", i, i - 1);
  refused(t, chain + " };", "structs nest deeper than 32 levels");
  std::string sequences = "module deep { struct S { ";
  for (int i = 0; i < 40; ++i) sequences += "sequence<";
  refused(t, sequences + "long" + std::string(40, '>') + " s; }; };",
          "modules or sequences nest deeper than 32 levels");
  refused(t, "module acme { struct Leaf { double a; }; };",
          "struct 'acme::Leaf' is declared here already, with other members");
  t.add("module acme { struct Leaf { long a; }; struct Other { Leaf l; }; };");  // the same again
  EXPECT_TRUE(t.has("acme::Other"));
  for (const auto* gone : {"evil::A", "evil::B", "deep::S0", "deep::S"}) EXPECT_FALSE(t.has(gone));
  ASSERT_NE(t.members("acme::Leaf"), nullptr);
  EXPECT_EQ(t.members("acme::Leaf")->at(0).type.name, "long") << "the refused text changed nothing";
}

// The encoder writes what the compiled type support writes: byte for byte.
TEST(IdlTypes, EncodesYamlAsTheCompiledTypeSupportEncodesTheSameValue) {
  ConfigCommand c;
  c.id(1ull << 40);
  c.sender("coordinator");
  c.kind(CMD_COMMAND);
  c.args({"cam", "frame_mode"});
  c.payload_type("oscar::SetFrameMode");
  c.payload({0, 1, 0, 0, 255});
  EXPECT_EQ(
      oscar_types().from_yaml("oscar::ConfigCommand",
                              YAML::Load("{id: 1099511627776, sender: coordinator, kind: "
                                         "CMD_COMMAND, args: [cam, frame_mode], payload_type: "
                                         "'oscar::SetFrameMode', payload: [0, 1, 0, 0, 255]}")),
      bytes_of_plain(c));
}

TEST(IdlTypes, EncodesNestedStructsArraysAndSequencesThatTheCompiledTypeDecodes) {
  const auto bytes = oscar_types().from_yaml("oscar::CameraImage", YAML::Load(R"(
header: { stamps: [5, 6], source: cam/frame, seq: 3 }
camera_id: cam
width: 2
height: 1
fx: 0.5
position: [1, -2.5, 3]
data: [7, 8]
truth: { valid: true, tags: [ { id: -4, pose: { t: [1, 2, 3], q: [1, 0, 0, 0] } } ] }
)"));
  const auto decoded = cue_type_info<CameraImage>().deserialize(bytes);
  const auto& f = *static_cast<const CameraImage*>(decoded.get());
  ASSERT_EQ(f.header().stamps().size(), 2u);
  EXPECT_EQ(f.header().stamps()[1], 6u);
  EXPECT_EQ(f.header().source(), "cam/frame");
  EXPECT_EQ(f.header().seq(), 3u);
  EXPECT_EQ(f.camera_id(), "cam");
  EXPECT_EQ(f.encoding(), "") << "a member the YAML leaves out takes its default";
  EXPECT_EQ(f.width(), 2);
  EXPECT_DOUBLE_EQ(f.fx(), 0.5);
  EXPECT_DOUBLE_EQ(f.fy(), 0);
  EXPECT_DOUBLE_EQ(f.position()[1], -2.5);
  EXPECT_EQ(f.data(), (std::vector<std::uint8_t>{7, 8}));
  EXPECT_TRUE(f.truth().valid());
  ASSERT_EQ(f.truth().tags().size(), 1u);
  EXPECT_EQ(f.truth().tags()[0].id(), -4);
  EXPECT_DOUBLE_EQ(f.truth().tags()[0].pose().t()[2], 3);
  EXPECT_DOUBLE_EQ(f.truth().tags()[0].corners()[7], 0);
}

TEST(IdlTypes, YamlThatDoesNotFitTheTypeIsAnErrorNamingTheMemberAndTheRule) {
  const auto types = oscar_types();
  const auto error = [&](const std::string& type, const std::string& yaml) -> std::string {
    try {
      types.from_yaml(type, YAML::Load(yaml));
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(error("oscar::SetFrameMode", "{mod: half}"),
            "oscar::SetFrameMode has no member 'mod' (members: mode)");
  EXPECT_EQ(error("oscar::SetFrameMode", "half"),
            "oscar::SetFrameMode is a struct: give a map of its members");
  EXPECT_EQ(error("oscar::SetFrameMode", "{mode: [half]}"), "mode: expected a string");
  EXPECT_EQ(error("oscar::CameraImage", "{width: 70000}"),
            "width: 70000 is out of the range of unsigned short (0..65535)");
  EXPECT_EQ(error("oscar::CameraImage", "{width: -1}"), "width: '-1' is no unsigned short");
  EXPECT_EQ(error("oscar::CameraImage", "{fx: wide}"), "fx: 'wide' is no double");
  EXPECT_EQ(error("oscar::CameraImage", "{position: [1, 2]}"),
            "position: expected a list of 3 items, got 2");
  EXPECT_EQ(error("oscar::CameraImage", "{truth: {tags: [{id: 1.5}]}}"),
            "truth.tags[0].id: '1.5' is no long");
  EXPECT_EQ(error("oscar::ConfigCommand", "{kind: CMD_JUMP}"),
            "kind: 'CMD_JUMP' is no enumerator of oscar::CommandKind (CMD_ACTIVATE, "
            "CMD_DEACTIVATE, CMD_TRIGGER, CMD_SET_CYCLE, CMD_SET_PARAM, CMD_REWIRE, CMD_SUSPEND, "
            "CMD_RESUME, CMD_STUB, CMD_SHUTDOWN, CMD_COMMAND)");
  EXPECT_EQ(error("oscar::Nope", "{}"), "unknown IDL type 'oscar::Nope'");
}

}  // namespace
}  // namespace oscar::inspect
