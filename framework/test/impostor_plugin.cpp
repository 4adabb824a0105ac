// The test_impostor kernel, a plugin for oscar-run children of the integration tests: it tries
// what the retired sequencer did, configuring another module under the coordinator's name from a
// DDS participant of its own inside its module's process. Each cycle it asks `target` to activate
// all its kernels and logs the module's verdict ("impostor: accepted" or "impostor: refused: ...").
// With `ask: shutdown` it asks the registry to shut the system down instead, under the name it
// claims (the registry's verdict is in its own log). With `identity:` its participant
// authenticates as that identity of the keystore its module runs with ($OSCAR_KEYSTORE, which
// `oscar boot --keystore` exports): a module's own credentials, stolen from its process.
#include <memory>
#include <string>

#include "oscar/config_client.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/kernel.hpp"
#include "oscar/kernel_registry.hpp"
#include "oscar/network.hpp"
#include "oscar/security_files.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::test {

class Impostor final : public Kernel {
 public:
  struct Params {
    std::string target;
    std::string claim = "coordinator";
    std::string ask = "activate";
    std::string identity;
    void describe(ParamSpec& spec) {
      spec.field("target", target, "the module it tries to configure");
      spec.field("claim", claim, "the sender name it claims");
      spec.field("ask", ask, "activate (the target) or shutdown (the system, of the registry)");
      spec.field("identity", identity, "the keystore identity it authenticates as (none: plain)");
    }
  };
  explicit Impostor(KernelSetup& setup) { setup.params(params_); }

  void process(Cycle& cycle) override {
    if (!client_) {
      // The domain oscar-run exports, the default network (loopback).
      NetworkConfig network;
      if (!params_.identity.empty()) {
        network.security =
            ParticipantSecurity{security_files::keystore_from_env(), params_.identity};
      }
      participant_ = std::make_unique<DdsParticipant>(domain_from_env(0), "oscar-tool", network);
      client_ = std::make_unique<ConfigClient>(*participant_, params_.claim);
    }
    if (params_.ask == "shutdown") {
      if (!registry_) {
        registry_ = std::make_unique<TopicWriter<RegistryRequest, RegistryRequestPubSubType>>(
            *participant_, topics::registry_request());
      }
      RegistryRequest q;
      q.id(++requests_);
      q.sender(params_.claim);
      q.kind(REG_SHUTDOWN);
      registry_->write(q);
      cycle.log().info("impostor: asked the registry to shut the system down");
      return;
    }
    try {
      const auto reply = client_->send(params_.target, CMD_ACTIVATE, {"*"});
      if (reply.ok()) {
        cycle.log().info("impostor: accepted");
      } else {
        cycle.log().info("impostor: {}", reply.error());
      }
    } catch (const std::exception& e) {
      cycle.log().info("impostor: no answer: {}", e.what());
    }
  }
  void stub(Cycle&) override {}

 private:
  Params params_;
  std::unique_ptr<DdsParticipant> participant_;
  std::unique_ptr<ConfigClient> client_;
  std::unique_ptr<TopicWriter<RegistryRequest, RegistryRequestPubSubType>> registry_;
  unsigned long long requests_ = 0;
};

}  // namespace oscar::test

OSCAR_REGISTER_KERNEL(oscar::test::Impostor, "test_impostor")
