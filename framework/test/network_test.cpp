#include "oscar/network.hpp"

#include <cstdlib>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "dds/udp_tuning.hpp"  // framework/src

namespace oscar {
namespace {

TEST(NetworkBadInput, AnUnknownDdsLogLevelNamesTheVariableAndTheLevels) {
  setenv("OSCAR_DDS_LOG", "verbose", 1);
  try {
    dds_log_level_from_env();
    ADD_FAILURE() << "accepted OSCAR_DDS_LOG=verbose";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "OSCAR_DDS_LOG='verbose': expected error, warning or info");
  }
  setenv("OSCAR_DDS_LOG", "warning", 1);
  EXPECT_NO_THROW(dds_log_level_from_env());
  unsetenv("OSCAR_DDS_LOG");
  EXPECT_NO_THROW(dds_log_level_from_env()) << "unset: Fast DDS's default";
}

TEST(NetworkBadInput, UdpSettingsOutOfRangeNameTheVariableAndTheRange) {
  const auto refused = [](const char* name, const char* value) {
    setenv(name, value, 1);
    std::string what;
    try {
      internal::udp_tuning(NetworkConfig{});
    } catch (const std::invalid_argument& e) {
      what = e.what();
    }
    unsetenv(name);
    return what;
  };
  EXPECT_EQ(refused("OSCAR_UDP_BUFFER_BYTES", "4M"),
            "OSCAR_UDP_BUFFER_BYTES='4M': expected 0 (the default) or a number of bytes from 65536 "
            "to 1073741824");
  EXPECT_EQ(refused("OSCAR_UDP_BUFFER_BYTES", "1000"),
            "OSCAR_UDP_BUFFER_BYTES='1000': expected 0 (the default) or a number of bytes from "
            "65536 to 1073741824");
  EXPECT_EQ(refused("OSCAR_UDP_BUFFER_BYTES", "-1"),
            "OSCAR_UDP_BUFFER_BYTES='-1': expected 0 (the default) or a number of bytes from 65536 "
            "to 1073741824");
  EXPECT_EQ(refused("OSCAR_UDP_MAX_MESSAGE_BYTES", "65536"),
            "OSCAR_UDP_MAX_MESSAGE_BYTES='65536': expected 0 (the default) or a number of bytes "
            "from 1024 to 65500");
  EXPECT_EQ(refused("OSCAR_UDP_MAX_MESSAGE_BYTES", "99999999999999999999"),
            "OSCAR_UDP_MAX_MESSAGE_BYTES='99999999999999999999': expected 0 (the default) or a "
            "number of bytes from 1024 to 65500");
}

TEST(NetworkBadInput, UdpKeysOutOfRangeNameTheKeyAndTheRange) {
  const auto refused = [](const char* yaml) {
    try {
      NetworkConfig::from_yaml(YAML::Load(yaml));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refused("{udp_buffer_bytes: 4MiB}"),
            "network.udp_buffer_bytes='4MiB': expected 0 (the default) or a number of bytes from "
            "65536 to 1073741824");
  EXPECT_EQ(refused("{udp_buffer_bytes: -4194304}"),
            "network.udp_buffer_bytes='-4194304': expected 0 (the default) or a number of bytes "
            "from 65536 to 1073741824");
  EXPECT_EQ(refused("{udp_max_message_bytes: 100}"),
            "network.udp_max_message_bytes='100': expected 0 (the default) or a number of bytes "
            "from 1024 to 65500");
}

TEST(NetworkBadInput, ASharedMemorySegmentSmallerThanAMessageNamesTheKeyAndTheRule) {
  try {
    NetworkConfig::from_yaml(YAML::Load("{shm_segment_bytes: 4096}"));
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "network.shm_segment_bytes: 4096 is smaller than 65536 (Fast DDS's largest "
                 "message through shared memory must fit)");
  }
}

// Unset, the segment follows what the participant sends; set, it is taken as it is.
TEST(Network, TheSharedMemorySegmentIsSmallForAParticipantThatPublishesNoCues) {
  const NetworkConfig unset;
  EXPECT_EQ(shm_segment_bytes_for(unset, true), kCueShmSegmentBytes);
  EXPECT_EQ(shm_segment_bytes_for(unset, false), kQuietShmSegmentBytes);
  EXPECT_LT(kQuietShmSegmentBytes, kCueShmSegmentBytes);
  const auto set = NetworkConfig::from_yaml(YAML::Load("{shm_segment_bytes: 2097152}"));
  EXPECT_EQ(shm_segment_bytes_for(set, true), 2u << 20);
  EXPECT_EQ(shm_segment_bytes_for(set, false), 2u << 20);
}

// The system file's (or module file's) `network:` map sets them; the environment, where set,
// overrides that for the participants a process makes (benchmarks, experiments).
TEST(Network, UdpSettingsComeFromTheNetworkMapAndTheEnvironmentOverridesThem) {
  unsetenv("OSCAR_UDP_BUFFER_BYTES");
  unsetenv("OSCAR_UDP_MAX_MESSAGE_BYTES");
  const NetworkConfig loopback;
  EXPECT_EQ(internal::udp_tuning(loopback).buffer_bytes, 4u << 20) << "room for a 442 KB image";
  EXPECT_EQ(internal::udp_tuning(loopback).max_message_bytes, 0u) << "0: Fast DDS's 65500";
  const auto tuned =
      NetworkConfig::from_yaml(YAML::Load("{udp_buffer_bytes: 8388608, udp_max_message_bytes: "
                                          "8972}"));
  EXPECT_EQ(internal::udp_tuning(tuned).buffer_bytes, 8u << 20);
  EXPECT_EQ(internal::udp_tuning(tuned).max_message_bytes, 8972u);
  const auto system_default = NetworkConfig::from_yaml(YAML::Load("{udp_buffer_bytes: 0}"));
  EXPECT_EQ(internal::udp_tuning(system_default).buffer_bytes, 0u) << "0: the system's default";
  setenv("OSCAR_UDP_BUFFER_BYTES", "0", 1);
  setenv("OSCAR_UDP_MAX_MESSAGE_BYTES", "1400", 1);
  const auto t = internal::udp_tuning(tuned);
  EXPECT_EQ(t.buffer_bytes, 0u);
  EXPECT_EQ(t.max_message_bytes, 1400u);
  unsetenv("OSCAR_UDP_BUFFER_BYTES");
  unsetenv("OSCAR_UDP_MAX_MESSAGE_BYTES");
}

}  // namespace
}  // namespace oscar
