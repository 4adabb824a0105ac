// The registry's journal: what a registry started after a crash reads back (docs/boot.md).
#include "registry_journal.hpp"

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar::internal {
namespace {
using ::testing::HasSubstr;

RegistryJournal sample() {
  RegistryJournal j;
  j.written = 1'764'000'000'123'456'789;
  JournalModule sink;
  sink.name = "sink";
  sink.incarnation = 3;
  sink.restore = "{sink: {mode: single_step, stub: false, params: {log_every: 700ms}}}";
  sink.restarts = 2;
  sink.counted = {1'764'000'000'000'000'000, 1'764'000'000'100'000'000};
  sink.last_failure = "killed by signal 9 (last output: \"x: y\")";
  sink.status = "restarting";
  sink.restart_at = 1'764'000'000'200'000'000;
  JournalModule src;
  src.name = "src";
  src.incarnation = 1;
  src.status = "replaced";
  src.replaced_by = "spare_src";
  j.modules = {sink, src};
  return j;
}

std::string temp_file(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("oscar_journal_test_" + name)).string();
}

TEST(RegistryJournal, WhatIsWrittenIsReadBack) {
  const auto j = sample();
  EXPECT_EQ(RegistryJournal::parse(j.to_yaml(), "j.yaml"), j);
  const auto file = temp_file("roundtrip.yaml");
  j.write(file);
  EXPECT_FALSE(std::filesystem::exists(file + ".tmp")) << "the temporary file is renamed";
  const auto back = RegistryJournal::read(file);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(*back, j);
  std::filesystem::remove(file);
}

TEST(RegistryJournal, AMissingFileIsNoJournal) {
  EXPECT_FALSE(RegistryJournal::read(temp_file("never_written.yaml")).has_value());
}

TEST(RegistryJournal, ATornFileIsRefusedNamingTheFile) {
  const auto text = sample().to_yaml();
  const auto file = temp_file("torn.yaml");
  std::ofstream(file) << text.substr(0, text.size() / 2);
  try {
    RegistryJournal::read(file);
    FAIL() << "a journal cut in half was read";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr(file));
  }
  std::filesystem::remove(file);
}

TEST(RegistryJournal, GarbledTextIsRefusedWithWhatIsWrong) {
  EXPECT_THROW(RegistryJournal::parse("{{{ not yaml", "j.yaml"), std::invalid_argument);
  try {
    RegistryJournal::parse("modules: []\nend: true\n", "j.yaml");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("j.yaml: not a registry journal"));
  }
  auto text = sample().to_yaml();
  text.replace(text.find("incarnation: 3"), 14, "incarnation: x");
  try {
    RegistryJournal::parse(text, "j.yaml");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("j.yaml: modules[0]: 'incarnation' is not a number"));
  }
}

}  // namespace
}  // namespace oscar::internal
