// A disk that fills up mid-recording (a 2 MiB tmpfs): oscar record stops with a clear error
// naming the file and the reason, and what it had written out before — its complete chunks —
// is on disk and readable, every cue whole and in order (issue 4, bad input).
#include <sys/mount.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/config_client.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/mcap/reader.hpp"
#include "process.hpp"  // tests/common

namespace oscar {
namespace {
using namespace std::chrono_literals;
using test::Process;

// A tmpfs of `size` mounted for the test, unmounted afterwards.
class SmallDisk {
 public:
  explicit SmallDisk(const std::string& size) : dir_(test::temp_path("small_disk")) {
    std::filesystem::create_directories(dir_);
    const auto options = "size=" + size;
    mounted_ = mount("tmpfs", dir_.c_str(), "tmpfs", 0, options.c_str()) == 0;
  }
  ~SmallDisk() {
    if (mounted_) umount2(dir_.c_str(), MNT_DETACH);
    std::filesystem::remove_all(dir_);
  }
  bool mounted() const { return mounted_; }
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
  bool mounted_ = false;
};

TEST(RecordDisk, AFullDiskIsAClearErrorAndTheWrittenChunksStayReadable) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to mount a 2 MiB tmpfs";
  SmallDisk disk("2m");
  ASSERT_TRUE(disk.mounted()) << "mount tmpfs: " << std::strerror(errno);
  const auto file = disk.dir() + "/full.mcap";
  const auto domain = std::to_string(test::test_domain());
  // 768x576 images (442 KB each) at 20 Hz: the 2 MiB are full after about five.
  Process source({test::bin("oscar-run"), "--name", "cam", "--domain", domain, "-k",
                  "bench_source:cam", "-p", "cam.type=GvImage", "-m", "deactivated"},
                 test::temp_path("disk_cam.log"));
  Process rec({test::bin("oscar-record"), "-o", file, "--domain", domain, "--compression", "none",
               "cam/out"},
              test::temp_path("disk_record.log"));
  const auto until = std::chrono::steady_clock::now() + 15s;
  while (rec.output().find("recording oscar/cue/cam/out") == std::string::npos) {
    ASSERT_LT(std::chrono::steady_clock::now(), until) << rec.output();
    std::this_thread::sleep_for(20ms);
  }
  std::this_thread::sleep_for(1s);
  DdsParticipant participant(test::test_domain(), "record_disk_test");
  ConfigClient coordinator(participant, "coordinator");
  ASSERT_TRUE(coordinator.send("cam", CMD_ACTIVATE, {"cam", "continuous:50ms"}).ok());

  const auto rc = rec.wait(30s);
  ASSERT_TRUE(rc.has_value()) << "the recorder kept running on a full disk: " << rec.output();
  EXPECT_EQ(*rc, 1);
  EXPECT_THAT(rec.output(), testing::ContainsRegex("oscar record: cannot write MCAP file '" + file +
                                                   "' at byte [0-9]+: No space left on device"));
  // What reached the disk: complete chunks, every image whole, seq 1..n without a gap.
  mcap::Reader reader(file);
  std::vector<std::uint64_t> seqs;
  const auto scan = reader.read_messages([&](const mcap::Channel&, const mcap::MessageView& m) {
    const std::vector<std::uint8_t> bytes(m.data.begin(), m.data.end());
    const auto g = std::static_pointer_cast<GvImage>(cue_type_info<GvImage>().deserialize(bytes));
    EXPECT_EQ(g->image().size(), 768u * 576u);
    seqs.push_back(g->header().seq());
  });
  EXPECT_TRUE(scan.truncation.has_value()) << "the file has no end: the disk was full";
  ASSERT_GE(seqs.size(), 1u) << "a complete chunk was written before the disk filled";
  for (std::size_t i = 0; i < seqs.size(); ++i) EXPECT_EQ(seqs[i], i + 1);
  Process info({test::bin("oscar-info"), file}, test::temp_path("disk_info.log"));
  ASSERT_TRUE(info.wait(20s).has_value());
  EXPECT_THAT(info.output(), testing::HasSubstr("oscar/cue/cam/out")) << info.output();
}

}  // namespace
}  // namespace oscar
