// oscar record of the plain cue types (docs/zero_copy.md): the recorder reads their fixed-size
// header by the type's name (sequence and publish time come from it) and writes their IDL as the
// schema; every image comes back whole.
#include <csignal>
#include <filesystem>
#include <map>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/cue_type_info.hpp"
#include "oscar/mcap/reader.hpp"
#include "oscar/testing/eventually.hpp"
#include "plain_kernels.hpp"  // framework/test
#include "process.hpp"        // tests/common

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::Process;
using testing::HasSubstr;

TEST(PlainRecord, RecordsPlainCuesWithTheSequenceAndTimeOfTheirHeaderAndTheirIdl) {
  const auto file = test::temp_path("record_plain.mcap");
  std::filesystem::remove(file);
  const auto domain = std::to_string(test::test_domain());
  Process rec({test::bin("oscar-record"), "-o", file, "--domain", domain, "pr/image", "pr/flag"},
              test::temp_path("record_plain.log"));
  Process src({test::bin("oscar-run"), "--name", "pr", "--domain", domain, "--plugin",
               test::build_dir() + "/lib/oscar/test_plugins/liboscar_kernel_test_plain.so", "-k",
               "test_plain_source:pr", "-m", "continuous:50ms"},
              test::temp_path("record_plain_src.log"));
  ASSERT_TRUE(eventually([&] { return rec.output().find("pr/image") != std::string::npos; }, 30s))
      << rec.output() << src.output();
  std::this_thread::sleep_for(3s);
  kill(rec.pid(), SIGINT);
  ASSERT_EQ(rec.wait(10s), 0) << rec.output();
  mcap::Reader reader(file);
  const auto info = reader.info();
  std::map<std::string, std::uint64_t> messages;
  std::uint64_t last_image_seq = 0;
  reader.read_messages([&](const mcap::Channel& c, const mcap::MessageView& m) {
    ++messages[c.topic];
    const auto& schema = info.schemas.at(c.schema_id);
    EXPECT_EQ(schema.encoding, "omgidl");
    EXPECT_THAT(std::string(schema.data.begin(), schema.data.end()),
                HasSubstr("struct PlainCueHeader"));
    const std::vector<std::uint8_t> bytes(m.data.begin(), m.data.end());
    if (c.topic == "oscar/cue/pr/image") {
      EXPECT_EQ(schema.name, "oscar::PlainGvImage");
      const auto image =
          std::static_pointer_cast<PlainGvImage>(cue_type_info<PlainGvImage>().deserialize(bytes));
      const auto header = cue_type_info<PlainGvImage>().header.read(image.get());
      EXPECT_TRUE(test::plain_image_complete(*image)) << "seq " << header.seq();
      // Read by the recorder from the bytes, laid out as the type's name says.
      EXPECT_EQ(m.sequence, header.seq());
      EXPECT_GT(m.sequence, last_image_seq);
      last_image_seq = m.sequence;
      ASSERT_EQ(header.stamps().size(), 1u);
      EXPECT_EQ(m.publish_time, header.stamps()[0]);
    } else {
      EXPECT_EQ(c.topic, "oscar/cue/pr/flag");
      EXPECT_EQ(schema.name, "oscar::PlainBool");
      const auto flag =
          std::static_pointer_cast<PlainBool>(cue_type_info<PlainBool>().deserialize(bytes));
      EXPECT_EQ(m.sequence, flag->header().seq());
      EXPECT_EQ(flag->value(), flag->header().seq() % 2 == 1);
    }
  });
  EXPECT_GE(messages["oscar/cue/pr/image"], 20u) << "~3 s at 20 Hz";
  EXPECT_GE(messages["oscar/cue/pr/flag"], 20u);
}

}  // namespace
}  // namespace oscar
