#include "oscar/network.hpp"

#include <cstdlib>

#include <gtest/gtest.h>

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
      internal::udp_tuning_from_env();
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

TEST(Network, UdpSettingsComeFromTheEnvironmentAndBuffersDefaultTo4MiB) {
  unsetenv("OSCAR_UDP_BUFFER_BYTES");
  unsetenv("OSCAR_UDP_MAX_MESSAGE_BYTES");
  EXPECT_EQ(internal::udp_tuning_from_env().buffer_bytes, 4u << 20);
  EXPECT_EQ(internal::udp_tuning_from_env().max_message_bytes, 0u);
  setenv("OSCAR_UDP_BUFFER_BYTES", "0", 1);
  EXPECT_EQ(internal::udp_tuning_from_env().buffer_bytes, 0u) << "0: the system's default";
  setenv("OSCAR_UDP_BUFFER_BYTES", "4194304", 1);
  setenv("OSCAR_UDP_MAX_MESSAGE_BYTES", "8972", 1);
  const auto t = internal::udp_tuning_from_env();
  EXPECT_EQ(t.buffer_bytes, 4194304u);
  EXPECT_EQ(t.max_message_bytes, 8972u);
  unsetenv("OSCAR_UDP_BUFFER_BYTES");
  unsetenv("OSCAR_UDP_MAX_MESSAGE_BYTES");
}

}  // namespace
}  // namespace oscar
