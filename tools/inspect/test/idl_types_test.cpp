#include "idl_types.hpp"

#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <oscar/config.h>
#include <oscar/configPubSubTypes.h>
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/idl_texts.hpp"

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

}  // namespace
}  // namespace oscar::inspect
