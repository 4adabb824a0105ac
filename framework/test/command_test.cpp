// Command ports (docs/kernels.md, "Command ports"): declaration, the harness, and the frame's
// delivery on the processing thread, without DDS.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/command_types.hpp"
#include "oscar/harness.hpp"
#include "oscar/module.hpp"
#include "oscar/testing/eventually.hpp"
#include "test_kernels.hpp"

namespace oscar {
namespace {
using testing::HasSubstr;

Bool flag(bool value) {
  Bool b;
  b.value(value);
  return b;
}

SetFrameMode frame_mode(const std::string& mode) {
  SetFrameMode m;
  m.mode(mode);
  return m;
}

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

// A kernel whose constructor declares what the test gives it.
class Declaring final : public Kernel {
 public:
  explicit Declaring(KernelSetup& setup, const std::vector<std::string>& names) {
    for (const auto& n : names) {
      setup.command<Bool>(n, [](const Bool&) { return CommandAnswer::accept(); });
    }
  }
  void process(Cycle&) override {}
  void stub(Cycle&) override {}
};

std::string declaration_error(const std::vector<std::string>& names) {
  KernelPorts ports("k");
  KernelSetup setup("k", "declaring", ports);
  return error_of([&] { Declaring d(setup, names); });
}

TEST(CommandPorts, ADuplicateCommandNameIsRefusedAtDeclaration) {
  EXPECT_EQ(declaration_error({"hold", "hold"}),
            "kernel 'k' (declaring): command 'hold' is declared twice; command names are unique "
            "per kernel");
  EXPECT_THAT(declaration_error({"go home"}),
              HasSubstr("command name 'go home' must be an identifier"));
  EXPECT_EQ(declaration_error({"hold", "release"}), "no error");
}

TEST(CommandPorts, TheHarnessDeliversACommandAndReturnsTheKernelsAnswer) {
  KernelHarness h("test_commanded");
  auto answer = h.command("hold", flag(true));
  EXPECT_TRUE(answer.accepted);
  EXPECT_THAT(answer.text, HasSubstr("held"));
  answer = h.command("hold", flag(false));
  EXPECT_FALSE(answer.accepted);
  EXPECT_EQ(answer.text, "told not to hold");
  EXPECT_TRUE(h.command("mode", frame_mode("half")).accepted);
  EXPECT_EQ(dynamic_cast<test::Commanded&>(h.kernel()).mode_, "half");
}

TEST(CommandPorts, AnUnknownCommandIsAnErrorListingTheKernelsCommands) {
  KernelHarness h("test_commanded", {}, "arm");
  EXPECT_EQ(
      error_of([&] { h.command("jump", flag(true)); }),
      "kernel 'arm' (test_commanded) has no command 'jump'; its commands: hold (oscar::Bool), "
      "mode (oscar::SetFrameMode)");
}

TEST(CommandPorts, ACommandToAKernelThatDeclaresNoneIsAnError) {
  KernelHarness h("test_counter", {}, "src");
  EXPECT_EQ(error_of([&] { h.command("hold", flag(true)); }),
            "kernel 'src' (test_counter) has no command 'hold': it declares no commands");
}

TEST(CommandPorts, ARequestOfAnotherTypeIsRefusedNamingBothTypes) {
  KernelHarness h("test_commanded", {}, "arm");
  EXPECT_EQ(error_of([&] { h.command("hold", frame_mode("half")); }),
            "command 'hold' of kernel 'arm' takes oscar::Bool, not oscar::SetFrameMode");
}

TEST(CommandPorts, APayloadThatDoesNotDecodeAsTheDeclaredTypeIsAnError) {
  KernelHarness h("test_commanded", {}, "arm");
  // A CDR string whose length runs past the end of the payload.
  const std::vector<std::uint8_t> truncated{0, 1, 0, 0, 0xff, 0xff, 0, 0, 'h', 'a'};
  EXPECT_THAT(error_of([&] { h.command_cdr("mode", "oscar::SetFrameMode", truncated); }),
              HasSubstr("command 'mode' of kernel 'arm': the payload is no oscar::SetFrameMode "
                        "(malformed oscar::SetFrameMode: 10 bytes are no valid CDR encoding)"));
  EXPECT_THAT(error_of([&] { h.command_cdr("mode", "oscar::SetFrameMode", {}); }),
              HasSubstr("0 bytes are no valid CDR encoding"));
  EXPECT_EQ(dynamic_cast<test::Commanded&>(h.kernel()).mode_, "") << "the kernel saw nothing";
}

// --- in a module ------------------------------------------------------------------------------

ModuleSpec spec(const std::string& yaml) {
  return ModuleSpec::from_yaml(YAML::Load(yaml), "test.yaml");
}

const char* const kArm = R"(
name: arm
mode: { continuous: 1ms }
kernels:
  - { type: test_commanded, name: arm }
  - { type: test_collect, name: sink, inputs: { in: arm/out } }
)";

ConfigCommand command(const std::string& kernel, const std::string& name, const auto& request,
                      std::string sender = "coordinator") {
  using T = std::decay_t<decltype(request)>;
  ConfigCommand c;
  c.id(1);
  c.sender(std::move(sender));
  c.kind(CMD_COMMAND);
  c.args({kernel, name});
  c.payload_type(idl_type_info<T>().name);
  c.payload(idl_type_info<T>().serialize(&request));
  return c;
}

test::Commanded& arm(Module& m) { return dynamic_cast<test::Commanded&>(m.kernel("arm").kernel()); }

TEST(ModuleCommands, TheKernelAnswersOnItsProcessingThreadBetweenCycles) {
  Module m(spec(kArm), {});
  m.start(-1);
  ASSERT_TRUE(eventually([&] { return arm(m).cycles_ >= 3; }));
  for (int i = 0; i < 20; ++i) {
    const auto reply = m.apply(command("arm", "hold", flag(true)));
    ASSERT_TRUE(reply.ok()) << reply.error();
    EXPECT_TRUE(reply.answered());
    EXPECT_EQ(reply.answer(), "held; on the processing thread: yes; during process(): no");
  }
  const auto refused = m.apply(command("arm", "hold", flag(false)));
  EXPECT_FALSE(refused.ok());
  EXPECT_TRUE(refused.answered());
  EXPECT_EQ(refused.answer(), "told not to hold");
  EXPECT_EQ(refused.error(), "command 'hold' refused by kernel 'arm': told not to hold");
  EXPECT_EQ(arm(m).commands_, 21);
}

TEST(ModuleCommands, TheStateListsEachKernelsCommands) {
  Module m(spec(kArm), {});
  const auto st = m.state();
  ASSERT_EQ(st.kernels()[0].commands().size(), 2u);
  EXPECT_EQ(st.kernels()[0].commands()[0].name(), "hold");
  EXPECT_EQ(st.kernels()[0].commands()[0].type(), "oscar::Bool");
  EXPECT_EQ(st.kernels()[0].commands()[1].name(), "mode");
  EXPECT_EQ(st.kernels()[0].commands()[1].type(), "oscar::SetFrameMode");
  EXPECT_TRUE(st.kernels()[1].commands().empty());
}

TEST(ModuleCommands, ADeactivatedKernelOrASuspendedModuleRefusesCommands) {
  Module m(spec(kArm), {});
  m.start(-1);
  ASSERT_TRUE(m.apply(command("arm", "hold", flag(true))).ok());
  ConfigCommand deactivate;
  deactivate.sender("coordinator");
  deactivate.kind(CMD_DEACTIVATE);
  deactivate.args({"arm"});
  ASSERT_TRUE(m.apply(deactivate).ok());
  auto reply = m.apply(command("arm", "hold", flag(true)));
  EXPECT_FALSE(reply.ok());
  EXPECT_FALSE(reply.answered());
  EXPECT_EQ(reply.error(),
            "command failed: kernel 'arm' is deactivated; a kernel takes commands only while it "
            "is activated");
  ConfigCommand suspend;
  suspend.sender("registry");
  suspend.kind(CMD_SUSPEND);
  ASSERT_TRUE(m.apply(suspend).ok());
  reply = m.apply(command("sink", "hold", flag(true)));
  EXPECT_THAT(reply.error(), HasSubstr("it declares no commands")) << "checked before the mode";
  ConfigCommand activate;
  activate.sender("coordinator");
  activate.kind(CMD_ACTIVATE);
  activate.args({"arm", "single_step"});
  ASSERT_TRUE(m.apply(activate).ok());
  reply = m.apply(command("arm", "hold", flag(true)));
  EXPECT_EQ(reply.error(),
            "command failed: module 'arm' is suspended; its kernels take commands again once it "
            "resumes");
  EXPECT_EQ(arm(m).commands_, 1);
}

TEST(ModuleCommands, AnActivatedKernelThatHasNotRunYetIsActivatedBeforeItsFirstCommand) {
  Module m(spec(R"(
name: arm
mode: single_step
kernels:
  - { type: test_commanded, name: arm, mode: { single_step: { trigger: command } } }
)"),
           {});
  m.start(-1);
  EXPECT_EQ(arm(m).activations_, 0);
  ASSERT_TRUE(m.apply(command("arm", "hold", flag(true))).ok());
  EXPECT_EQ(arm(m).activations_, 1);
  EXPECT_EQ(arm(m).cycles_, 0) << "a command is no trigger";
}

TEST(ModuleCommands, OnlyTheCoordinatorAndBootMayCommandAKernel) {
  Module m(spec(kArm), {});
  m.start(-1);
  for (const std::string sender : {"registry", "some_module"}) {
    const auto reply = m.apply(command("arm", "hold", flag(true), sender));
    EXPECT_FALSE(reply.ok()) << sender;
    EXPECT_THAT(reply.error(), HasSubstr("refused: '" + sender + "' may not command module 'arm'"));
  }
  EXPECT_TRUE(m.apply(command("arm", "hold", flag(true), "boot")).ok());
  EXPECT_EQ(arm(m).commands_, 1);
}

TEST(ModuleCommands, BadCommandsAreRefusedBeforeTheyReachTheKernel) {
  Module m(spec(kArm), {});
  m.start(-1);
  auto reply = m.apply(command("arm", "jump", flag(true)));
  EXPECT_THAT(reply.error(), HasSubstr("has no command 'jump'; its commands: hold (oscar::Bool)"));
  reply = m.apply(command("arm", "hold", frame_mode("half")));
  EXPECT_THAT(reply.error(), HasSubstr("takes oscar::Bool, not oscar::SetFrameMode"));
  auto garbled = command("arm", "mode", frame_mode("half"));
  garbled.payload().resize(6);
  reply = m.apply(garbled);
  EXPECT_THAT(reply.error(), HasSubstr("the payload is no oscar::SetFrameMode"));
  auto no_name = command("arm", "hold", flag(true));
  no_name.args({"arm"});
  EXPECT_THAT(m.apply(no_name).error(),
              HasSubstr("command takes 2 argument(s) (kernel, command name), got 1"));
  ConfigCommand trigger_with_payload = command("arm", "hold", flag(true));
  trigger_with_payload.kind(CMD_TRIGGER);
  trigger_with_payload.args({"arm"});
  EXPECT_THAT(m.apply(trigger_with_payload).error(),
              HasSubstr("only a command (CMD_COMMAND) carries a payload"));
  EXPECT_FALSE(reply.answered());
  EXPECT_EQ(arm(m).commands_, 0);
}

TEST(ModuleCommands, AHandlerThatThrowsIsAKernelFailure) {
  Module m(spec(kArm), {});
  m.start(-1);
  const auto reply = m.apply(command("arm", "mode", frame_mode("boom")));
  EXPECT_FALSE(reply.ok());
  EXPECT_FALSE(reply.answered());
  EXPECT_THAT(reply.error(), HasSubstr("kernel 'arm' failed in command mode: boom"));
  EXPECT_EQ(reply.state().kernels()[0].failures(), 1u);
  EXPECT_EQ(reply.state().kernels()[0].last_failure(), "command mode: boom");
}

}  // namespace
}  // namespace oscar
