#include "oscar/security_files.hpp"

#include <unistd.h>

#include <fstream>
#include <map>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace oscar::security_files {
namespace {

using ::testing::HasSubstr;

class SecurityFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    keystore_ = std::filesystem::temp_directory_path() /
                ("oscar_security_files_" + std::to_string(getpid()));
    std::filesystem::remove_all(keystore_);
    std::filesystem::create_directories(identity_dir(keystore_, "module.camera"));
  }
  void TearDown() override { std::filesystem::remove_all(keystore_); }
  void touch(const char* file) {
    std::ofstream(identity_dir(keystore_, "module.camera") / file) << "x";
  }
  std::filesystem::path keystore_;
};

TEST_F(SecurityFiles, NamesIdentitiesAfterWhatRunsAsThem) {
  EXPECT_EQ(module_identity("camera"), "module.camera");
  EXPECT_EQ(monitor_identity("robot1"), "monitor.robot1");
  EXPECT_EQ(identity_dir("/k", "registry"), std::filesystem::path("/k/identities/registry"));
}

TEST_F(SecurityFiles, PropertiesPointFastDdsAtTheIdentitysOwnFiles) {
  for (const auto* f :
       {kIdentityCa, kCertificate, kPrivateKey, kPermissionsCa, kGovernance, kPermissions}) {
    touch(f);
  }
  const auto list = dds_security_properties(keystore_, "module.camera");
  const std::map<std::string, std::string> p(list.begin(), list.end());
  ASSERT_EQ(p.size(), list.size()) << "a property given twice";
  const auto file = [&](const char* name) {
    return "file://" + (keystore_ / "identities" / "module.camera" / name).string();
  };
  EXPECT_EQ(p.at("dds.sec.auth.plugin"), "builtin.PKI-DH");
  EXPECT_EQ(p.at("dds.sec.auth.builtin.PKI-DH.identity_ca"), file("identity_ca.cert.pem"));
  EXPECT_EQ(p.at("dds.sec.auth.builtin.PKI-DH.identity_certificate"), file("cert.pem"));
  EXPECT_EQ(p.at("dds.sec.auth.builtin.PKI-DH.private_key"), file("key.pem"));
  EXPECT_EQ(p.at("dds.sec.access.plugin"), "builtin.Access-Permissions");
  EXPECT_EQ(p.at("dds.sec.access.builtin.Access-Permissions.permissions_ca"),
            file("permissions_ca.cert.pem"));
  EXPECT_EQ(p.at("dds.sec.access.builtin.Access-Permissions.governance"), file("governance.p7s"));
  EXPECT_EQ(p.at("dds.sec.access.builtin.Access-Permissions.permissions"), file("permissions.p7s"));
  EXPECT_EQ(p.at("dds.sec.crypto.plugin"), "builtin.AES-GCM-GMAC");
  EXPECT_EQ(p.size(), 9u);
}

TEST_F(SecurityFiles, AMissingFileIsNamedWithTheCommandThatMakesIt) {
  touch(kIdentityCa);
  touch(kCertificate);
  try {
    dds_security_properties(keystore_, "module.camera");
    ADD_FAILURE() << "accepted an identity without a private key";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("identity 'module.camera' has no "));
    EXPECT_THAT(e.what(), HasSubstr("module.camera/key.pem (run `oscar security init`)"));
  }
}

}  // namespace
}  // namespace oscar::security_files
