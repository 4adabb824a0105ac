#include "oscar/params.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

namespace oscar {
namespace {
using testing::HasSubstr;
using testing::ThrowsMessage;

struct Params {
  std::string family = "tag36h11";
  double tag_size_m = 0.16;
  int threads = 1;
  bool refine = true;
  std::chrono::nanoseconds timeout = std::chrono::milliseconds(100);
  void describe(ParamSpec& spec) {
    spec.field("family", family, "tag family").one_of({"tag36h11", "tag25h9"});
    spec.field("tag_size_m", tag_size_m, "edge length").range(0.001, 10);
    spec.field("threads", threads, "worker threads").at_least(1);
    spec.field("refine", refine, "refine edges");
    spec.field("timeout", timeout, "give up after");
  }
};

TEST(ParamSpec, SetsEveryTypeFromYaml) {
  Params p;
  ParamSpec spec("kernel 'k'");
  p.describe(spec);
  spec.set_all(
      YAML::Load("{family: tag25h9, tag_size_m: 0.2, threads: 4, refine: false, timeout: 2s}"));
  EXPECT_EQ(p.family, "tag25h9");
  EXPECT_DOUBLE_EQ(p.tag_size_m, 0.2);
  EXPECT_EQ(p.threads, 4);
  EXPECT_FALSE(p.refine);
  EXPECT_EQ(p.timeout, std::chrono::seconds(2));
}

TEST(ParamSpec, RoundTripsThroughYaml) {
  Params a, b;
  ParamSpec sa("a"), sb("b");
  a.describe(sa);
  b.describe(sb);
  sa.set_all(
      YAML::Load("{family: tag25h9, tag_size_m: 0.25, threads: 3, refine: false, timeout: 15ms}"));
  sb.set_all(YAML::Load(sa.to_yaml()));
  EXPECT_EQ(sb.to_yaml(), sa.to_yaml());
  EXPECT_EQ(b.family, "tag25h9");
  EXPECT_EQ(b.timeout, std::chrono::milliseconds(15));
}

TEST(ParamSpec, TypeErrorsNameTheParameterAndTheType) {
  Params p;
  ParamSpec spec("kernel 'k'");
  p.describe(spec);
  EXPECT_THAT([&] { spec.set_text("tag_size_m", "abc"); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("kernel 'k': parameter 'tag_size_m' expects a double, got 'abc'")));
  EXPECT_THAT([&] { spec.set_text("threads", "2.5"); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("'threads' expects a int")));
  EXPECT_THAT([&] { spec.set_text("refine", "maybe"); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("'refine' expects a bool")));
  EXPECT_THAT([&] { spec.set_text("timeout", "5"); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("parameter 'timeout': duration '5'")));
  EXPECT_THAT([&] { spec.set_text("tag_size_m", "nan"); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("expects a double")));
}

TEST(ParamSpec, RangesAndChoicesAreChecked) {
  Params p;
  ParamSpec spec("kernel 'k'");
  p.describe(spec);
  EXPECT_THAT([&] { spec.set_text("threads", "0"); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("'threads' = 0 is outside its range [1, inf]")));
  EXPECT_THAT([&] { spec.set_text("family", "tag16h5"); },
              ThrowsMessage<std::invalid_argument>(
                  HasSubstr("'tag16h5' is not one of: tag36h11, tag25h9")));
  EXPECT_EQ(p.threads, 1) << "a refused value leaves the old one";
}

TEST(ParamSpec, UnknownNamesListTheKnownOnes) {
  Params p;
  ParamSpec spec("kernel 'k'");
  p.describe(spec);
  EXPECT_THAT([&] { spec.set_text("fmaily", "x"); },
              ThrowsMessage<std::invalid_argument>(HasSubstr(
                  "kernel 'k' has no parameter 'fmaily'; its parameters: family, tag_size_m")));
}

TEST(ParamSpec, ParamsMustBeAMap) {
  Params p;
  ParamSpec spec("kernel 'k'");
  p.describe(spec);
  EXPECT_THAT([&] { spec.set_all(YAML::Load("[1, 2]")); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("params must be a map")));
}

}  // namespace
}  // namespace oscar
