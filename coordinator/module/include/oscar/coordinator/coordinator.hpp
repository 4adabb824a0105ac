#pragma once
/// @file The coordinator (docs/coordinator.md): binds the applet scheduler to running modules.
/// Services are modules: granting a service configures its provider modules as the system file
/// says (activate in a mode), idling it deactivates them. Applets run in threads of their own
/// (the scheduler's Runtime) and command the modules of the services they hold through it; it is
/// the only configuration authority for modules. It publishes its plan on oscar/coordinator/plan.
/// Applets configured with a `process:` run in processes of their own and keep their slot here,
/// driven over DDS (oscar/sched/..., AppletHost on their side).

#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <oscar/coordinator.h>

#include "oscar/applets/config.hpp"
#include "oscar/applets/runtime.hpp"
#include "oscar/config_client.hpp"
#include "oscar/coordinator/applet.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/registry/system_spec.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::coordinator {

class KernelWishes;
class Providers;
class RemoteApplets;

class Coordinator final : public AppletGateway {
 public:
  /// Builds the model from the system file's services and applets and makes every applet (from
  /// a registered type or its plugin on `plugin_path`). Nothing runs yet.
  /// @throws std::invalid_argument "file:line: ..." for an applet that cannot be made.
  Coordinator(const SystemSpec& system, DdsParticipant& participant,
              const std::vector<std::string>& plugin_path);
  ~Coordinator() override;
  Coordinator(const Coordinator&) = delete;
  Coordinator& operator=(const Coordinator&) = delete;

  /// Starts the applets' threads and the thread that configures the providers and publishes
  /// the plan.
  void start();
  /// Stops the applets and the coordinator's thread (also called by the destructor).
  void stop();

  ConfigReply command(const std::string& applet, const std::string& service,
                      const std::string& module, const std::string& kernel,
                      const std::string& command, const std::string& type,
                      std::vector<std::uint8_t> cdr) override;
  ConfigReply trigger(const std::string& applet, const std::string& service,
                      const std::string& module, const std::string& kernel) override;
  std::string bundle_name(applets::BundleId bundle) const override;

  /// The plan as it is now (what the coordinator publishes).
  AppletPlan plan();

  /// An operator's event for an applet's bundle (what the coordinator kernel's command port
  /// `applet` takes): request, release, trigger, yield, set_priority, set_deadline, negotiate,
  /// and crash for an applet in another process. An applet in another process applies it as
  /// its own call; this returns once it did. Also `add` (add_spec) and `remove` (remove_applet
  /// or, with `service` set, remove_service). Returns why it was refused, if it was.
  std::optional<std::string> apply_event(const AppletEvent& event);

  /// Adds services and applets while the system runs (docs/coordinator.md, "Adding and removing
  /// at run time"): `spec` is YAML with `services:` (as in the system file) and/or `applets:`
  /// (as `coordinator: applets:` entries, in this process); `name` names it in messages. Added
  /// services configure their providers as the file's do; added applets start at once. All or
  /// nothing. Returns why it was refused ("name:line: ..."), if it was.
  std::optional<std::string> add_spec(const std::string& spec, const std::string& name);
  /// Removes an applet: its bundles are released, the services it provides become unavailable,
  /// its thread ends. Returns why it was refused, if it was.
  std::optional<std::string> remove_applet(const std::string& applet);
  /// Removes a service nobody uses. Returns why it was refused (the applets whose bundles use
  /// it, the services that need it), if it was.
  std::optional<std::string> remove_service(const std::string& service);

 private:
  struct Snapshot;
  Snapshot snapshot();  // under the runtime's lock
  void loop();
  void on_system_state(const SystemState& state);
  // Applies what the snapshot's services need to their providers, then publishes if changed.
  void reconcile();
  void wake();
  // An applet's command or trigger: refused unless `module`/`kernel` provides `service` and
  // `applet` holds it now.
  std::optional<ConfigReply> refuse_unless_held(const std::string& applet,
                                                const std::string& service,
                                                const std::string& module,
                                                const std::string& kernel);
  // Refused unless the providers of `service` are (or become) configured for its holder; with
  // reconcile_mutex_ held.
  std::optional<ConfigReply> await_providers(const std::string& service, const std::string& module);
  // What the runtime runs for an applet made here.
  applets::AppletCode code_of(Applet* applet);
  // Adds what `addition` (read from `root`, named `name`) says; `remote` names the process of
  // an applet joining from another process (its hello), else empty. With change_mutex_ held.
  // `root` (a spec named `name`) checked against the system's services as they are now.
  SystemAddition read_addition(const YAML::Node& root, const std::string& name);
  void add_locked(const SystemAddition& addition, const YAML::Node& root, const std::string& name,
                  const std::string& remote);
  // Removes an applet; `by_operator` keeps its joined process's session from joining again.
  std::optional<std::string> remove_applet(const std::string& applet, bool by_operator);
  // A hello with a spec from an applet the coordinator does not know.
  std::optional<std::string> join(const std::string& applet, const std::string& process,
                                  const std::string& spec);

  const SystemSpec& system_;
  DdsParticipant& participant_;  // applets added at run time read cues through it
  std::vector<std::string> plugin_path_;
  applets::SystemConfig config_;
  std::unique_ptr<applets::Runtime> runtime_;
  std::vector<std::unique_ptr<Applet>> applets_;        // by AppletId; with change_mutex_ held
  std::mutex change_mutex_;                             // one addition or removal at a time
  mutable std::mutex services_mutex_;                   // guards the next two
  std::vector<ServiceSpec> services_;                   // the file's and those added since
  std::vector<std::vector<std::string>> providers_of_;  // by ServiceId, as the plan shows them
  std::unique_ptr<ConfigClient> client_;
  std::unique_ptr<Providers> providers_;
  std::unique_ptr<RemoteApplets> remote_;
  std::unique_ptr<KernelWishes> wishes_;
  TopicWriter<AppletPlan, AppletPlanPubSubType> plan_writer_;
  std::unique_ptr<TopicReader<SystemState, SystemStatePubSubType>> system_reader_;

  std::mutex reconcile_mutex_;  // one reconciliation at a time (the loop or a command)
  std::mutex mutex_;            // what follows
  std::condition_variable wake_;
  bool stopping_ = false;
  bool started_ = false;
  bool woken_ = false;  // something to reconcile before the next tick
  struct KnownModule {  // what the registry reports of a module
    bool running = false;
    unsigned long incarnation = 0;
    bool ran = false;  // seen running at least once
  };
  std::map<std::string, KnownModule> modules_;
  AppletPlan published_;
  bool published_any_ = false;
  std::thread thread_;
};

}  // namespace oscar::coordinator
