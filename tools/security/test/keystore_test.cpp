#include "keystore.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/security_files.hpp"
#include "pki.hpp"

namespace oscar::security {
namespace {

namespace fs = std::filesystem;
using ::testing::Contains;
using ::testing::HasSubstr;
using Clock = std::chrono::system_clock;

constexpr const char* kSystem = R"(
system: t
modules:
  - { name: camera, kernels: [ { type: bench_source, name: cam } ] }
  - { name: viewer, kernels: [ { type: bench_sink, name: view, inputs: { in: cam/out } } ] }
)";

SystemSpec system_of(const std::string& extra = "") {
  return SystemSpec::parse(YAML::Load(std::string(kSystem) + extra), "t.yaml");
}

std::string read(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

unsigned mode_of(const fs::path& path) {
  struct stat st {};
  ::stat(path.c_str(), &st);
  return st.st_mode & 0777;
}

std::vector<std::string> texts(const std::vector<Finding>& found, Finding::Level level) {
  std::vector<std::string> out;
  for (const auto& f : found) {
    if (f.level == level) out.push_back(f.text);
  }
  return out;
}
std::vector<std::string> errors(const std::vector<Finding>& f) {
  return texts(f, Finding::Level::kError);
}
std::vector<std::string> warnings(const std::vector<Finding>& f) {
  return texts(f, Finding::Level::kWarning);
}

class Keystore : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("oscar_keystore_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name()) /
           "keys";
    fs::remove_all(dir_.parent_path());
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }
  fs::path identity(const std::string& name) const {
    return security_files::identity_dir(dir_, name);
  }
  fs::path dir_;
};

TEST_F(Keystore, InitLaysOutEveryIdentityForFastDdsWithPrivateKeysOwnerOnly) {
  const auto said = init_keystore(system_of(), dir_);
  EXPECT_THAT(said,
              Contains(HasSubstr("created identity module.camera (CN=module.camera,O=OSCAR")));
  EXPECT_EQ(mode_of(dir_), 0700u);
  EXPECT_EQ(mode_of(dir_ / "private" / "identity_ca.key.pem"), 0600u);
  EXPECT_EQ(mode_of(dir_ / "private" / "permissions_ca.key.pem"), 0600u);
  for (const auto* name : {"registry", "boot", "operator", "operator_boot", "monitor.localhost",
                           "module.camera", "module.viewer"}) {
    EXPECT_EQ(mode_of(identity(name) / "key.pem"), 0600u) << name;
    EXPECT_NO_THROW(security_files::dds_security_properties(dir_, name)) << name;
  }
  // The grant names the certificate's subject exactly as Fast DDS prints it.
  const auto cert = pki::read_cert(identity("module.camera") / "cert.pem");
  EXPECT_EQ(pki::subject(*cert), "CN=module.camera,O=OSCAR");
  EXPECT_THAT(read(identity("module.camera") / "permissions.xml"),
              HasSubstr("<subject_name>CN=module.camera,O=OSCAR</subject_name>"));
  EXPECT_TRUE(check_keystore(system_of(), dir_).empty());
}

TEST_F(Keystore, InitAgainKeepsEverythingAndSaysSo) {
  init_keystore(system_of(), dir_);
  const auto key = read(identity("module.camera") / "key.pem");
  const auto ca = read(dir_ / "public" / "identity_ca.cert.pem");
  const auto permissions = read(identity("module.camera") / "permissions.p7s");
  const auto said = init_keystore(system_of(), dir_);
  EXPECT_THAT(said, ::testing::ElementsAre(
                        HasSubstr("kept identity_ca"), HasSubstr("kept permissions_ca"),
                        "kept governance (cue protection: none)", "kept 7 identities unchanged"));
  EXPECT_EQ(read(identity("module.camera") / "key.pem"), key);
  EXPECT_EQ(read(dir_ / "public" / "identity_ca.cert.pem"), ca);
  EXPECT_EQ(read(identity("module.camera") / "permissions.p7s"), permissions);
}

TEST_F(Keystore, ANewModuleGetsAnIdentityAndTheOthersKeepTheirKeys) {
  init_keystore(system_of(), dir_);
  const auto key = read(identity("module.camera") / "key.pem");
  const auto grown =
      system_of("  - { name: lidar, kernels: [ { type: bench_source, name: lid } ] }\n");
  EXPECT_THAT(errors(check_keystore(grown, dir_)),
              ::testing::ElementsAre(HasSubstr("module.lidar: missing")));
  EXPECT_THAT(init_keystore(grown, dir_), Contains(HasSubstr("created identity module.lidar")));
  EXPECT_EQ(read(identity("module.camera") / "key.pem"), key);
  EXPECT_TRUE(check_keystore(grown, dir_).empty());
  // Back to the smaller system: the lidar's identity is extra, left in place and reported.
  EXPECT_THAT(warnings(check_keystore(system_of(), dir_)),
              ::testing::ElementsAre(HasSubstr("module.lidar: not in the system file")));
  EXPECT_THAT(init_keystore(system_of(), dir_), Contains(HasSubstr("left identity module.lidar")));
}

TEST_F(Keystore, AChangedGraphOrCueProtectionRewritesWhatItChanges) {
  init_keystore(system_of(), dir_);
  const auto rewired = SystemSpec::parse(YAML::Load(R"(
system: t
modules:
  - { name: camera, kernels: [ { type: bench_source, name: cam } ] }
  - { name: viewer, kernels: [ { type: bench_sink, name: view2 } ] }
security: { cue_protection: encrypt }
)"),
                                         "t.yaml");
  const auto found = errors(check_keystore(rewired, dir_));
  EXPECT_THAT(found, Contains(HasSubstr("governance differs from what the system file gives (cue "
                                        "protection: encrypt")));
  EXPECT_THAT(found, Contains(HasSubstr("module.viewer: permissions differ")));
  EXPECT_EQ(found.size(), 2u);
  const auto said = init_keystore(rewired, dir_);
  EXPECT_THAT(said, Contains("rewrote governance (cue protection: encrypt)"));
  EXPECT_THAT(said, Contains("updated identity module.viewer: rewrote its permissions"));
  EXPECT_THAT(said, Contains("kept 6 identities unchanged"));
  EXPECT_THAT(read(dir_ / "public" / "governance.xml"),
              HasSubstr("<data_protection_kind>ENCRYPT</data_protection_kind>"));
  EXPECT_TRUE(check_keystore(rewired, dir_).empty());
}

TEST_F(Keystore, CheckWarnsBeforeExpiryAndFailsAfter) {
  init_keystore(system_of(), dir_);
  const auto until = pki::not_after(*pki::read_cert(identity("boot") / "cert.pem"));
  const auto soon = check_keystore(system_of(), dir_, until - std::chrono::hours(24 * 10));
  EXPECT_THAT(warnings(soon), Contains(HasSubstr("boot: certificate expires in 10 days (")));
  EXPECT_THAT(warnings(soon), Contains(HasSubstr("; `oscar security init` renews it")));
  EXPECT_TRUE(errors(soon).empty());
  const auto ca_until = pki::not_after(*pki::read_cert(dir_ / "public" / "identity_ca.cert.pem"));
  EXPECT_THAT(warnings(check_keystore(system_of(), dir_, ca_until - std::chrono::hours(24 * 5))),
              Contains(HasSubstr("identity_ca: certificate expires in 5 days (")));
  EXPECT_THAT(warnings(check_keystore(system_of(), dir_, ca_until - std::chrono::hours(24 * 5))),
              Contains(HasSubstr("init does not renew a CA: make a new keystore")));
  const auto late = check_keystore(system_of(), dir_, until + std::chrono::hours(1));
  EXPECT_THAT(errors(late), Contains(HasSubstr("boot: certificate expired on")));
}

TEST_F(Keystore, InitRenewsACertificateAboutToExpireWithTheSameKey) {
  KeystoreSettings short_lived;
  short_lived.identity_validity = std::chrono::hours(24 * 10);
  init_keystore(system_of(), dir_, short_lived);
  const auto key = read(identity("boot") / "key.pem");
  EXPECT_THAT(init_keystore(system_of(), dir_),
              Contains(HasSubstr("updated identity boot: renewed its certificate")));
  EXPECT_EQ(read(identity("boot") / "key.pem"), key);
  EXPECT_TRUE(check_keystore(system_of(), dir_).empty());
}

TEST_F(Keystore, CheckFindsForgedPermissionsForeignCertificatesAndOpenKeys) {
  init_keystore(system_of(), dir_);
  init_keystore(system_of(), dir_.parent_path() / "other");
  // Widen a module's permissions without the permissions CA.
  auto smime = read(identity("module.viewer") / "permissions.p7s");
  smime.replace(smime.find("oscar/cue/view/*"), 16, "oscar/cue/*     ");
  std::ofstream(identity("module.viewer") / "permissions.p7s") << smime;
  // A certificate (and key) of another keystore's CA.
  for (const auto* f : {"cert.pem", "key.pem"}) {
    fs::copy_file(dir_.parent_path() / "other" / "identities" / "module.camera" / f,
                  identity("module.camera") / f, fs::copy_options::overwrite_existing);
  }
  fs::permissions(identity("boot") / "key.pem", fs::perms::others_read, fs::perm_options::add);
  const auto found = errors(check_keystore(system_of(), dir_));
  EXPECT_THAT(found, Contains(HasSubstr("module.viewer: permissions not signed by the permissions "
                                        "CA")));
  EXPECT_THAT(found, Contains(HasSubstr("module.camera: certificate not issued by the identity "
                                        "CA")));
  EXPECT_THAT(found, Contains(HasSubstr("boot: ")));
  EXPECT_THAT(found, Contains(HasSubstr("key.pem is readable by others (chmod 600)")));
  // init repairs all three.
  init_keystore(system_of(), dir_);
  EXPECT_TRUE(check_keystore(system_of(), dir_).empty());
}

TEST_F(Keystore, DeletingAnIdentitysFolderAndRunningInitRotatesItsKey) {
  init_keystore(system_of(), dir_);
  const auto key = read(identity("module.camera") / "key.pem");
  fs::remove_all(identity("module.camera"));
  EXPECT_THAT(init_keystore(system_of(), dir_),
              Contains(HasSubstr("created identity module.camera")));
  EXPECT_NE(read(identity("module.camera") / "key.pem"), key);
  EXPECT_TRUE(check_keystore(system_of(), dir_).empty());
}

TEST_F(Keystore, ACaWithoutItsKeyIsRefusedRatherThanReplaced) {
  init_keystore(system_of(), dir_);
  fs::remove(dir_ / "private" / "identity_ca.key.pem");
  try {
    init_keystore(system_of(), dir_);
    ADD_FAILURE() << "replaced a CA whose key was missing";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("identity_ca.cert.pem but not"));
  }
}

TEST_F(Keystore, InitRefusesAFolderThatHoldsSomethingElse) {
  fs::create_directories(dir_);
  std::ofstream(dir_ / "notes.txt") << "mine";
  fs::permissions(dir_, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec,
                  fs::perm_options::replace);
  try {
    init_keystore(system_of(), dir_);
    ADD_FAILURE() << "took over a folder that is no keystore";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("exists and is no keystore (it has no identities/ folder)"));
  }
  EXPECT_EQ(mode_of(dir_), 0750u) << "its mode was changed";
  fs::remove(dir_ / "notes.txt");
  EXPECT_NO_THROW(init_keystore(system_of(), dir_)) << "an empty folder is fine";
}

TEST_F(Keystore, ListShowsWhatEachIdentityMayPublishFromItsSignedPermissions) {
  init_keystore(system_of(), dir_);
  const auto listed = list_keystore(dir_);
  ASSERT_EQ(listed.size(), 7u);
  EXPECT_EQ(listed.front().name, "boot");  // sorted
  for (const auto& l : listed) {
    EXPECT_TRUE(l.problem.empty()) << l.name << ": " << l.problem;
    if (l.name == "module.viewer") {
      EXPECT_EQ(l.subject, "CN=module.viewer,O=OSCAR");
      EXPECT_THAT(l.publish, Contains("oscar/cue/view/*"));
      EXPECT_THAT(l.publish, Contains("oscar/pull/cam/out/request"));
    }
    if (l.name == "operator") {
      EXPECT_TRUE(l.publish.empty());
    }
  }
}

}  // namespace
}  // namespace oscar::security
