// A configuration command is refused, naming the field and the rule, when a field is longer than
// its limit or its kind is no CommandKind; what a module quotes of it is an excerpt.
#include "command_bounds.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/module.hpp"
#include "test_kernels.hpp"

namespace oscar {
namespace {
using testing::HasSubstr;
using testing::Not;

ConfigCommand command(CommandKind kind, std::vector<std::string> args,
                      std::string sender = "coordinator") {
  ConfigCommand c;
  c.id(1);
  c.sender(std::move(sender));
  c.kind(kind);
  c.args(std::move(args));
  return c;
}

constexpr const char* kChain = R"(
name: chain
mode: deactivated
kernels:
  - { type: test_counter, name: src }
  - { type: test_collect, name: sink, inputs: { in: src/out } }
)";

std::unique_ptr<Module> chain() {
  const std::vector<std::string> no_plugins;
  return std::make_unique<Module>(ModuleSpec::from_yaml(YAML::Load(kChain), "test.yaml"),
                                  no_plugins);
}

TEST(CommandBounds, ACommandWithinEveryLimitIsNotMalformed) {
  EXPECT_EQ(internal::malformed(command(CMD_REWIRE, {"sink", "in", "src/out", "2s"})),
            std::nullopt);
  const std::string longest_sender(internal::kMaxSenderChars, 's');
  EXPECT_EQ(internal::malformed(command(CMD_SUSPEND, {}, longest_sender)), std::nullopt);
}

TEST(CommandBounds, ASenderOverItsLimitIsRefusedWithAnExcerpt) {
  const auto why = internal::malformed(command(CMD_SUSPEND, {}, std::string(256 * 1024, 'x')));
  ASSERT_TRUE(why);
  EXPECT_THAT(*why, HasSubstr("refused: sender is 262144 bytes long ('xxxx"));
  EXPECT_THAT(*why, HasSubstr("over the limit of 64"));
  EXPECT_LT(why->size(), 200u);
}

TEST(CommandBounds, AnArgumentOverItsLimitIsNamedByPosition) {
  const auto why =
      internal::malformed(command(CMD_SET_PARAM, {"src", "p", std::string(512 * 1024, 'v')}));
  ASSERT_TRUE(why);
  EXPECT_THAT(*why, HasSubstr("argument 3 is 524288 bytes long"));
  EXPECT_THAT(*why, HasSubstr("over the limit of 4096"));
  EXPECT_LT(why->size(), 200u);
}

TEST(CommandBounds, TooManyArgumentsAndLongPayloadsAreRefused) {
  EXPECT_THAT(internal::malformed(command(CMD_ACTIVATE, std::vector<std::string>(9, "a"))),
              testing::Optional(HasSubstr("9 arguments, over the limit of 8")));
  auto c = command(CMD_COMMAND, {"arm", "hold"});
  c.payload_type(std::string(300, 't'));
  EXPECT_THAT(internal::malformed(c),
              testing::Optional(HasSubstr("payload_type is 300 bytes long")));
  c.payload_type("oscar::Bool");
  c.payload(std::vector<std::uint8_t>(internal::kMaxPayloadBytes + 1));
  EXPECT_THAT(internal::malformed(c),
              testing::Optional(HasSubstr("payload is 1048577 bytes, over the limit of 1048576")));
}

TEST(CommandBounds, AKindOutsideCommandKindIsRefusedWithItsValue) {
  const auto why = internal::malformed(command(static_cast<CommandKind>(4711), {}));
  EXPECT_THAT(why, testing::Optional(HasSubstr("kind 4711 is no CommandKind (known: 0 activate "
                                               "to 10 command")));
}

TEST(CommandBounds, AnExcerptCutsBetweenCharactersAndSaysHowMuchIsLeftOut) {
  EXPECT_EQ(internal::excerpt("short"), "short");
  EXPECT_EQ(internal::excerpt("abcdef", 3), "abc... (3 more bytes)");
  // "é" is two bytes: a cut after the first would leave half a character.
  EXPECT_EQ(internal::excerpt("ab\xC3\xA9z", 3), "ab... (3 more bytes)");
}

TEST(CommandBounds, AModuleAnswersAnUnknownKindWithARefusal) {
  auto m = chain();
  const auto reply = m->apply(command(static_cast<CommandKind>(11), {"*"}));
  EXPECT_FALSE(reply.ok());
  EXPECT_THAT(reply.error(), HasSubstr("kind 11 is no CommandKind"));
  EXPECT_EQ(reply.state().kernels()[0].mode(), "deactivated");
}

TEST(CommandBounds, AModuleQuotesNoMoreThanAnExcerptOfAnOverLongArgument) {
  auto m = chain();
  const std::string huge(512 * 1024, 'v');
  for (const auto& c : {command(CMD_SET_PARAM, {"src", "count", huge}),
                        command(CMD_DEACTIVATE, {huge}), command(CMD_SUSPEND, {}, huge)}) {
    const auto reply = m->apply(c);
    EXPECT_FALSE(reply.ok());
    EXPECT_THAT(reply.error(), HasSubstr("over the limit of"));
    EXPECT_LT(reply.error().size(), 200u);
    EXPECT_THAT(reply.state().last_transition(), Not(HasSubstr(std::string(100, 'v'))));
  }
}

}  // namespace
}  // namespace oscar
