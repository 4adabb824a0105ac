#include "oscar/network.hpp"

#include <cstdlib>

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace oscar
