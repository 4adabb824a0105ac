// A system booted with a keystore (docs/security.md, "Secure boot"): every process authenticates
// as its own identity, and what each may write is enforced by Fast DDS across processes. A
// participant without credentials, or with another CA's, sees nothing and reaches nothing; a
// module's own credentials cannot configure another module; the read-only operator identity
// looks but cannot configure; only the registry may write launch requests; a killed module
// comes back with its identity. The keystore is made by each test (`oscar security init`).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "booted_system.hpp"
#include "oscar/config_client.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/security_files.hpp"
#include "oscar/testing/eventually.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "oscar/type_texts.hpp"
#include "source_tree.hpp"

// Fast DDS 2.9's PKI-DH plugin leaks what it allocated through OpenSSL for a handshake with a
// participant of another CA. Its frames are in libcrypto, whose stacks the fast unwinder cannot
// walk out of; unwound fully, they reach libfastrtps.so, which tests/sanitizers/lsan.supp names.
extern "C" __attribute__((used)) const char* __asan_default_options() {
  return "fast_unwind_on_malloc=0";
}

namespace oscar {
namespace {

using namespace std::chrono_literals;
using test::entry;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

// `rogue` tries, from inside its module's process and with that module's own credentials, to
// activate `cam`, as the coordinator would.
std::string secured_system() {
  return std::string("system: secure\nlease: 1s\nplugins: ") +
         oscar::testing::build_path("lib/oscar/test_plugins") + R"(
modules:
  - name: cam
    kernels: [ { type: bench_source, name: cam, params: { type: Bool } } ]
    mode: deactivated
  - name: signal
    kernels: [ { type: bench_source, name: signal, params: { type: Bool } } ]
    mode: { continuous: 20ms }
  - name: rogue
    kernels:
      - { type: test_impostor, name: rogue,
          params: { target: cam, identity: module.rogue }, mode: "continuous:300ms" }
)";
}

NetworkConfig as(const fs::path& keystore, const std::string& identity) {
  NetworkConfig network;
  network.security = ParticipantSecurity{keystore.string(), identity};
  return network;
}

std::string mode_of(const SystemState& s, const std::string& module) {
  const auto* m = entry(s, module);
  const auto* k = m ? test::kernel_state(*m, module) : nullptr;
  return k ? k->mode() : "";
}

class SecureSystem : public ::testing::Test {
 protected:
  void SetUp() override {
    keystore_ = test::temp_path("secure_keystore");
    fs::remove_all(keystore_);
    test::make_keystore("secure", secured_system(), keystore_);
    if (HasFatalFailure()) return;
    testing::BootOptions options;
    options.keystore = keystore_.string();
    system_ = std::make_unique<test::BootedSystem>("secure", secured_system(), options);
    system_->running();
  }
  void TearDown() override {
    system_.reset();
    fs::remove_all(keystore_);
  }

  // The topics `p` has discovered writers of within `wait`. (Participants it sees: DDS
  // Security leaves participant announcements unprotected, so that authentication can begin;
  // endpoints are announced only to authenticated participants.)
  static std::vector<std::string> topics_seen_by(DdsParticipant& p,
                                                 std::chrono::milliseconds wait) {
    std::this_thread::sleep_for(wait);
    std::vector<std::string> topics;
    for (const auto& [topic, writer] : p.discovered_writers()) topics.push_back(topic);
    return topics;
  }

  fs::path keystore_;
  std::unique_ptr<test::BootedSystem> system_;
};

TEST_F(SecureSystem, BootsWithEveryProcessAuthenticatedAndCuesFlow) {
  EXPECT_THAT(system_->boot_output(), HasSubstr("secured with keystore " + keystore_.string()));
  EXPECT_THAT(system_->boot_output(), ::testing::Not(HasSubstr("unauthenticated")));
  const auto s = system_->registry().latest();
  ASSERT_TRUE(s);
  for (const auto& m : s->modules()) EXPECT_EQ(m.status(), "running") << m.name();
  auto signal = system_->watch<Bool>("signal/out");
  EXPECT_TRUE(signal->wait_for(5, 10s)) << "no cue reached the operator_boot participant";
  // A read-only tool finds the keystore boot was given (its record) and runs as `operator`.
  test::Process ps({test::bin("oscar-ps"), "-d", std::to_string(system_->domain())},
                   test::temp_path("secure_ps.log"));
  ASSERT_EQ(ps.wait(30s), 0) << ps.output();
  EXPECT_THAT(ps.output(), HasSubstr("signal"));
  EXPECT_THAT(ps.output(), HasSubstr("rogue"));
}

TEST_F(SecureSystem, AParticipantWithoutCredentialsSeesNothingAndReachesNothing) {
  DdsParticipant outsider(system_->domain(), "outsider");
  testing::CueWatch<Bool> cues(outsider, "signal/out");
  EXPECT_THAT(topics_seen_by(outsider, 3s), ::testing::IsEmpty());
  EXPECT_EQ(cues.size(), 0u);
  ConfigClient client(outsider, "coordinator");
  EXPECT_ANY_THROW(client.send("cam", CMD_ACTIVATE, {"*", "continuous:100ms"}, 2s));
  // A launch request of its own starts nothing: no monitor ever hears it.
  TopicWriter<LaunchRequest, LaunchRequestPubSubType> launch(outsider, topics::launch());
  LaunchRequest forged;
  forged.host("localhost");
  forged.module_name("cam");
  forged.kind(LAUNCH_START);
  forged.incarnation(77);
  for (int i = 0; i < 10; ++i) {
    launch.write(forged);
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(launch.matched(), 0);
  EXPECT_THAT(test::processes_mentioning(std::string("--incarnation") + '\0' + "77"),
              ::testing::IsEmpty());
  EXPECT_EQ(mode_of(system_->registry().latest().value_or(SystemState{}), "cam"), "deactivated");
}

TEST_F(SecureSystem, AParticipantOfAnotherCaIsNotAuthenticated) {
  const auto foreign = test::temp_path("secure_foreign_keystore");
  fs::remove_all(foreign);
  test::make_keystore("foreign", secured_system(), foreign);
  {
    DdsParticipant stranger(system_->domain(), "stranger", as(foreign, "operator_boot"));
    testing::CueWatch<Bool> cues(stranger, "signal/out");
    EXPECT_THAT(topics_seen_by(stranger, 3s), ::testing::IsEmpty());
    EXPECT_EQ(cues.size(), 0u);
  }
  fs::remove_all(foreign);
}

TEST_F(SecureSystem, TamperedPermissionsAreRefusedWhenTheParticipantIsMade) {
  const auto copy = test::temp_path("secure_tampered");
  fs::remove_all(copy);
  fs::create_directories(copy + "/identities");
  fs::copy(keystore_ / "identities" / "operator", fs::path(copy) / "identities" / "operator",
           fs::copy_options::recursive | fs::copy_options::copy_symlinks);
  fs::copy(keystore_ / "public", fs::path(copy) / "public", fs::copy_options::recursive);
  // Grant the read-only operator every topic in the signed text, keeping the signature.
  const auto permissions = fs::path(copy) / "identities/operator/permissions.p7s";
  std::string text;
  {
    std::ifstream in(permissions);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto deny = text.find("<default>DENY</default>");
  ASSERT_NE(deny, std::string::npos);
  text.replace(deny, 23, "<default>ALLOW</default>");
  std::ofstream(permissions) << text;
  try {
    DdsParticipant forged(system_->domain(), "forged", as(copy, "operator"));
    ADD_FAILURE() << "a participant with tampered permissions was made";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("as identity 'operator'"));
    EXPECT_THAT(e.what(), HasSubstr("Fast DDS refused its security files"));
  }
  fs::remove_all(copy);
}

TEST_F(SecureSystem, AModulesOwnCredentialsCannotConfigureAnotherModule) {
  const std::string refused =
      "impostor: no answer: cannot create the configuration endpoints for module cam (identity "
      "'module.rogue'";
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (system_->boot_output().find(refused) == std::string::npos &&
         std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_THAT(system_->boot_output(), HasSubstr(refused));
  EXPECT_EQ(mode_of(system_->registry().latest().value_or(SystemState{}), "cam"), "deactivated");
}

TEST_F(SecureSystem, TheOperatorLooksButOnlyOperatorBootConfigures) {
  DdsParticipant look(system_->domain(), "operator", as(keystore_, "operator"));
  testing::CueWatch<Bool> cues(look, "signal/out");
  EXPECT_TRUE(cues.wait_for(5, 10s)) << "the operator identity reads no cue";
  ConfigClient denied(look, "boot");
  try {
    denied.send("cam", CMD_ACTIVATE, {"*", "continuous:100ms"}, 2s);
    ADD_FAILURE() << "the operator identity wrote a configuration command";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("identity 'operator'"));
  }
  // The test's own participant is operator_boot.
  const auto reply = system_->configure("cam", CMD_ACTIVATE, {"*", "continuous:100ms"});
  ASSERT_TRUE(reply.ok()) << reply.error();
  system_->wait_for([](const SystemState& s) { return mode_of(s, "cam") == "continuous"; });
}

TEST_F(SecureSystem, TheIdentityAWriterAuthenticatedAsDecidesNotTheSenderItNames) {
  // The registry's identity may suspend, not trigger: naming the coordinator does not help.
  DdsParticipant registry(system_->domain(), "registry-2", as(keystore_, "registry"));
  ConfigClient claims_coordinator(registry, "coordinator");
  const auto refused = claims_coordinator.send("cam", CMD_TRIGGER, {"cam"}, 10s);
  EXPECT_FALSE(refused.ok());
  EXPECT_THAT(refused.error(),
              HasSubstr("refused: the writer authenticated as 'registry' may not trigger module "
                        "'cam' (whatever sender it names, here 'coordinator')"));
  // Boot's authority holds under any name.
  DdsParticipant operator_boot(system_->domain(), "operator-2", as(keystore_, "operator_boot"));
  ConfigClient nameless(operator_boot, "someone");
  const auto reply = nameless.send("cam", CMD_ACTIVATE, {"*", "continuous:100ms"}, 10s);
  ASSERT_TRUE(reply.ok()) << reply.error();
  system_->wait_for([](const SystemState& s) { return mode_of(s, "cam") == "continuous"; });
}

TEST_F(SecureSystem, OnlyTheRegistryMayWriteLaunchRequests) {
  for (const auto* identity : {"boot", "operator_boot", "module.rogue", "monitor.localhost"}) {
    DdsParticipant p(system_->domain(), "forger", as(keystore_, identity));
    try {
      TopicWriter<LaunchRequest, LaunchRequestPubSubType> launch(p, topics::launch());
      ADD_FAILURE() << identity << " may write launch requests";
    } catch (const std::runtime_error& e) {
      EXPECT_THAT(e.what(), HasSubstr(std::string("identity '") + identity + "'"));
    }
  }
}

// The IDL texts of a module's own types (oscar/types) are for modules to announce: another
// identity is refused with an error naming it and the topic (a module started with a keystore
// made before OSCAR had the topic gets the same error, logs it and runs on).
TEST_F(SecureSystem, OnlyModulesMayAnnounceTheIdlTextsOfTheirTypes) {
  const std::map<std::string, std::string> texts{
      {"acme::Probe", "module acme { struct Probe { double value; }; };"}};
  for (const auto* identity : {"operator", "monitor.localhost", "registry"}) {
    DdsParticipant p(system_->domain(), "announcer", as(keystore_, identity));
    try {
      announce_type_texts(p, "signal", texts);
      ADD_FAILURE() << identity << " may announce IDL texts";
    } catch (const std::runtime_error& e) {
      EXPECT_THAT(e.what(), HasSubstr(std::string("identity '") + identity + "'"));
      EXPECT_THAT(e.what(), HasSubstr("may not publish on oscar/types"));
    }
  }
  DdsParticipant module(system_->domain(), "signal-2", as(keystore_, "module.signal"));
  EXPECT_NE(announce_type_texts(module, "signal", texts), nullptr);
}

TEST_F(SecureSystem, AKilledModuleIsRestartedWithItsIdentity) {
  const auto before = system_->registry().latest();
  ASSERT_TRUE(before);
  const auto* listed = entry(*before, "signal");
  ASSERT_NE(listed, nullptr) << "the registry does not list module 'signal'";
  const auto pid = listed->pid();
  ASSERT_EQ(kill(static_cast<pid_t>(pid), SIGKILL), 0);
  const auto after = system_->wait_for([&](const SystemState& s) {
    const auto* m = entry(s, "signal");
    return m && m->incarnation() == 2 && m->status() == "running";
  });
  EXPECT_NE(entry(after, "signal")->pid(), pid);
  auto signal = system_->watch<Bool>("signal/out");
  EXPECT_TRUE(signal->wait_for(5, 10s)) << "the restarted module's cues do not arrive";
}

TEST(UnsecuredSystem, BootSaysPlainlyThatItIsUnauthenticated) {
  test::BootedSystem sys("unsecured", std::string("system: unsecured\nplugins: ") +
                                          oscar::testing::build_path("lib/oscar/test_plugins") + R"(
modules:
  - name: signal
    kernels: [ { type: bench_source, name: signal, params: { type: Bool } } ]
)");
  sys.running();
  // Boot prints its merged log a moment late (it orders the records by time first), and a
  // one-module system can be running before that.
  const std::string warning = "unauthenticated: the system runs without DDS Security";
  EXPECT_TRUE(eventually([&] { return sys.boot_output().find(warning) != std::string::npos; }, 10s))
      << sys.boot_output();
}

}  // namespace
}  // namespace oscar
