// The keystore as Fast DDS's security plugins see it: participants of two identities of a small
// system, on loopback in this process, authenticate, match and deliver where the permissions
// allow it, and nowhere else (docs/security.md). Fast DDS logs each writer it refuses as a
// SECURITY error ("... topic not found in allow rule"): those lines are the point of the second
// test, not a failure.
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <thread>

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <gtest/gtest.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include "keystore.hpp"
#include "keystore_layout.hpp"
#include "oscar/configPubSubTypes.h"
#include "oscar/security_files.hpp"
#include "pki.hpp"
#include "process.hpp"  // tests/common: test_domain()

// Fast DDS's security plugins keep OpenSSL objects to the end of the process. Debian's libcrypto
// has no frame pointers, so ASan's fast unwinder stops inside it, and LeakSanitizer cannot see
// that those allocations come from Fast DDS (suppressed in tests/sanitizers/lsan.supp): unwind
// fully here. An ASAN_OPTIONS of the environment that names the flag still wins.
extern "C" const char* __asan_default_options() { return "fast_unwind_on_malloc=0"; }

namespace oscar::security {
namespace {

namespace dds = eprosima::fastdds::dds;
namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr const char* kSystem = R"(
system: secure
modules:
  - { name: talker, kernels: [ { type: bench_source, name: talker } ] }
  - { name: listener, kernels: [ { type: bench_sink, name: listener, inputs: { in: talker/out } } ] }
)";
constexpr const char* kCueTopic = "oscar/cue/talker/out";

constexpr int kParticipantIds = 8;

// One participant on loopback only: UDP on 127.0.0.1, discovery unicast to the well-known ports
// of participant ids 0..7 on this host (like OSCAR's own participants, network.hpp), with the
// DDS Security properties of an identity (none: an unauthenticated participant). Ids are given:
// Fast DDS counts its automatic ids up for the whole process, past the ports the peers name.
class Participant {
 public:
  Participant(int id, const std::vector<security_files::Property>& properties) {
    dds::DomainParticipantQos qos;
    qos.name("oscar-security-test");
    for (const auto& [name, value] : properties) {
      qos.properties().properties().emplace_back(name, value);
    }
    auto& transport = qos.transport();
    transport.use_builtin_transports = false;
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList = {"127.0.0.1"};
    transport.user_transports.push_back(udp);
    auto& builtin = qos.wire_protocol().builtin;
    builtin.avoid_builtin_multicast = true;
    const int domain = test::test_domain();
    for (int peer_id = 0; peer_id < kParticipantIds; ++peer_id) {
      eprosima::fastrtps::rtps::Locator_t peer;
      eprosima::fastrtps::rtps::IPLocator::setIPv4(peer, "127.0.0.1");
      // The metatraffic unicast port of RTPS 2.2 §9.6.1.1.
      peer.port = static_cast<std::uint32_t>(7400 + 250 * domain + 10 + 2 * peer_id);
      builtin.initialPeersList.push_back(peer);
    }
    qos.wire_protocol().participant_id = id;
    participant_ = dds::DomainParticipantFactory::get_instance()->create_participant(domain, qos);
    if (!participant_) return;
    type_.register_type(participant_);
    publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  }
  ~Participant() {
    if (!participant_) return;
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  bool ok() const { return participant_ != nullptr; }

  dds::DataWriter* writer(const std::string& topic) {
    dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
    qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    return publisher_->create_datawriter(this->topic(topic), qos);
  }
  dds::DataReader* reader(const std::string& topic) {
    dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
    qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    return subscriber_->create_datareader(this->topic(topic), qos);
  }

 private:
  dds::Topic* topic(const std::string& name) {
    auto& t = topics_[name];
    if (!t) t = participant_->create_topic(name, type_.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    return t;
  }
  dds::TypeSupport type_{new LogRecordPubSubType()};
  dds::DomainParticipant* participant_ = nullptr;
  dds::Publisher* publisher_ = nullptr;
  dds::Subscriber* subscriber_ = nullptr;
  std::map<std::string, dds::Topic*> topics_;
};

// The message of the first sample `reader` takes within `timeout`, or "" if none came.
std::string first_message(dds::DataReader& reader, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    LogRecord record;
    dds::SampleInfo info;
    if (reader.take_next_sample(&record, &info) == ReturnCode_t::RETCODE_OK && info.valid_data) {
      return record.message();
    }
    std::this_thread::sleep_for(20ms);
  }
  return "";
}

bool matched_within(dds::DataWriter& writer, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    dds::PublicationMatchedStatus status;
    writer.get_publication_matched_status(status);
    if (status.current_count > 0) return true;
    std::this_thread::sleep_for(20ms);
  }
  return false;
}

class SecureParticipants : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("oscar_secure_dds_" + std::to_string(getpid()));
    fs::remove_all(root_);
    const auto system = SystemSpec::parse(YAML::Load(kSystem), "secure.yaml");
    init_keystore(system, root_ / "keystore");  // cue_protection: none
    for (const auto* protection : {"sign", "encrypt"}) {
      init_keystore(
          SystemSpec::parse(YAML::Load(std::string(kSystem) +
                                       "security: { cue_protection: " + protection + " }\n"),
                            "secure.yaml"),
          root_ / (std::string("keystore_") + protection));
    }
    // The same system's identities, issued by CAs of another keystore.
    init_keystore(system, root_ / "foreign");
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  static std::vector<security_files::Property> as(const std::string& identity,
                                                  const char* keystore = "keystore") {
    return security_files::dds_security_properties(root_ / keystore, identity);
  }
  // A keystore `name` holding only module.listener's identity folder (its files copied), with
  // its certificate issued again by the first keystore's identity CA, valid until `validity`
  // from now (negative: expired).
  static void reissue_listener(const std::string& name, std::chrono::hours validity) {
    const auto from = root_ / "keystore";
    const auto folder = root_ / name / "identities" / "module.listener";
    fs::remove_all(root_ / name);
    fs::create_directories(folder.parent_path());
    fs::copy(from / "identities" / "module.listener", folder, fs::copy_options::recursive);
    const auto ca = pki::read_cert(layout::ca_cert_file(from, layout::kIdentityCaName));
    const auto ca_key = pki::read_key(layout::ca_key_file(from, layout::kIdentityCaName));
    const auto key = pki::read_key(folder / "key.pem");
    const auto cert = pki::issue(*key, "module.listener", ca.get(), *ca_key, validity, false);
    fs::remove(folder / "cert.pem");
    pki::write_cert(folder / "cert.pem", *cert);
  }
  static void send(dds::DataWriter& writer, const std::string& message) {
    LogRecord record;
    record.message(message);
    ASSERT_TRUE(writer.write(&record));
  }

  static fs::path root_;
};
fs::path SecureParticipants::root_;

// Cues travel with each protection a system file may choose; a configuration command (a control
// topic: signed, data encrypted) reaches the module from an identity with boot's authority.
TEST_F(SecureParticipants, AnAllowedWriterMatchesItsReaderAndDeliversASample) {
  for (const auto* keystore : {"keystore", "keystore_sign", "keystore_encrypt"}) {
    SCOPED_TRACE(keystore);
    Participant talker(0, as("module.talker", keystore));
    Participant listener(1, as("module.listener", keystore));
    ASSERT_TRUE(talker.ok()) << "Fast DDS refused the talker's keystore files";
    ASSERT_TRUE(listener.ok()) << "Fast DDS refused the listener's keystore files";
    auto* writer = talker.writer(kCueTopic);
    ASSERT_NE(writer, nullptr) << "module.talker may publish its own cue topic";
    auto* reader = listener.reader(kCueTopic);
    ASSERT_NE(reader, nullptr);
    ASSERT_TRUE(matched_within(*writer, 15s)) << "authenticated participants did not match";
    send(*writer, std::string("a cue from ") + keystore);
    EXPECT_EQ(first_message(*reader, 10s), std::string("a cue from ") + keystore);
  }
  Participant boot(0, as("operator_boot"));
  Participant talker(1, as("module.talker"));
  ASSERT_TRUE(boot.ok() && talker.ok());
  auto* commands = boot.writer("oscar/config/talker");
  ASSERT_NE(commands, nullptr);
  auto* inbox = talker.reader("oscar/config/talker");
  ASSERT_NE(inbox, nullptr);
  ASSERT_TRUE(matched_within(*commands, 15s));
  send(*commands, "configure");
  EXPECT_EQ(first_message(*inbox, 10s), "configure");
}

TEST_F(SecureParticipants, AnIdentityCannotCreateAWriterItsPermissionsDoNotGrant) {
  Participant listener(0, as("module.listener"));
  Participant op(1, as("operator"));
  Participant boot(2, as("operator_boot"));
  ASSERT_TRUE(listener.ok() && op.ok() && boot.ok());
  EXPECT_EQ(listener.writer(kCueTopic), nullptr) << "a module wrote another module's cue topic";
  EXPECT_EQ(listener.writer("oscar/config/talker"), nullptr)
      << "a module wrote another module's configuration topic";
  EXPECT_EQ(listener.writer("oscar/registry/launch"), nullptr) << "a module sent launch requests";
  EXPECT_EQ(op.writer("oscar/config/talker"), nullptr) << "the read-only operator configured";
  EXPECT_EQ(op.writer("oscar/registry/request"), nullptr);
  EXPECT_NE(boot.writer("oscar/config/talker"), nullptr) << "operator_boot has boot's authority";
  EXPECT_NE(listener.writer("oscar/config_reply/listener"), nullptr) << "its own replies";
  EXPECT_NE(op.reader("oscar/log"), nullptr) << "the operator reads";
}

TEST_F(SecureParticipants, AParticipantOfAnotherCaOrWithoutSecurityNeverMatches) {
  Participant talker(0, as("module.talker"));
  Participant listener(1, as("module.listener"));
  Participant impostor(2, as("module.listener", "foreign"));
  Participant plain(3, {});
  ASSERT_TRUE(talker.ok() && listener.ok() && impostor.ok() && plain.ok());
  auto* writer = talker.writer(kCueTopic);
  ASSERT_NE(writer, nullptr);
  auto* impostor_reader = impostor.reader(kCueTopic);
  auto* plain_reader = plain.reader(kCueTopic);
  auto* reader = listener.reader(kCueTopic);
  ASSERT_TRUE(impostor_reader && plain_reader && reader);
  // The genuine reader matching shows discovery works on this host: the others had the time.
  ASSERT_TRUE(matched_within(*writer, 15s));
  send(*writer, "for the genuine listener");
  EXPECT_EQ(first_message(*reader, 10s), "for the genuine listener");
  std::this_thread::sleep_for(2s);
  dds::PublicationMatchedStatus status;
  writer->get_publication_matched_status(status);
  EXPECT_EQ(status.current_count, 1) << "a reader other than the genuine one matched";
  EXPECT_EQ(first_message(*impostor_reader, 500ms), "") << "a foreign CA's identity got data";
  EXPECT_EQ(first_message(*plain_reader, 500ms), "") << "an unauthenticated reader got data";
}

// The listener's certificate issued again by the same CA: valid for another hour, the copied
// identity matches and receives (the copy is sound); expired an hour ago, it receives nothing,
// whether Fast DDS refuses it when the participant is made or in the handshake.
TEST_F(SecureParticipants, AnExpiredCertificateIsRefused) {
  reissue_listener("renewed", std::chrono::hours(1));
  reissue_listener("expired", std::chrono::hours(-1));
  Participant talker(0, as("module.talker"));
  ASSERT_TRUE(talker.ok());
  auto* writer = talker.writer(kCueTopic);
  ASSERT_NE(writer, nullptr);
  {
    Participant renewed(1, as("module.listener", "renewed"));
    ASSERT_TRUE(renewed.ok()) << "Fast DDS refused a valid re-issued certificate";
    auto* reader = renewed.reader(kCueTopic);
    ASSERT_NE(reader, nullptr);
    ASSERT_TRUE(matched_within(*writer, 15s)) << "the renewed identity did not match";
    send(*writer, "for the renewed listener");
    EXPECT_EQ(first_message(*reader, 10s), "for the renewed listener");
  }
  Participant expired(2, as("module.listener", "expired"));
  if (!expired.ok()) return;  // refused when the participant was made
  auto* reader = expired.reader(kCueTopic);
  ASSERT_NE(reader, nullptr);
  std::this_thread::sleep_for(3s);
  send(*writer, "for nobody expired");
  EXPECT_EQ(first_message(*reader, 1s), "") << "an expired certificate's participant got data";
}

}  // namespace
}  // namespace oscar::security
