#pragma once
/// @file Applets in any process (docs/coordinator.md, "Applets in other processes"): an
/// AppletHost runs applets of a system in this process against the system's running
/// coordinator, over DDS (oscar/sched/...). The applets are the same classes as in the
/// coordinator (OSCAR_REGISTER_APPLET); their AppletContext sends the scheduler's calls to the
/// coordinator and hears its notifications, and their commands go through the coordinator as a
/// local applet's do. `oscar-applet` is such a process; a test or a module's own process can
/// host applets the same way.

#include <memory>
#include <string>
#include <vector>

#include "oscar/coordinator/applet.hpp"
#include "oscar/dds_participant.hpp"
#include "oscar/registry/system_spec.hpp"

namespace oscar::coordinator {

class AppletHost {
 public:
  /// Makes the named applets of the system's `coordinator:` section (from registered types or
  /// plugins on `plugin_path`); `process` is the name the coordinator shows for this process.
  /// Nothing runs yet.
  /// @throws std::invalid_argument naming an applet the system does not configure, or one that
  ///         cannot be made.
  AppletHost(const SystemSpec& system, DdsParticipant& participant,
             const std::vector<std::string>& applets, std::string process,
             const std::vector<std::string>& plugin_path);
  /// Also hosts applets the system file does not configure, which join the running system
  /// (seed 000 §4.1.1): `joining` is YAML with `applets:` (entries as in `coordinator:
  /// applets:`, without process: and host:), `joining_file` names it in messages. Each one's
  /// hello carries its entry: the coordinator adds the applet at its first hello (and again
  /// after the coordinator restarts) and removes it when its lease runs out.
  /// @throws std::invalid_argument as above, and "file:line: ..." for a bad entry.
  AppletHost(const SystemSpec& system, DdsParticipant& participant,
             const std::vector<std::string>& applets, const YAML::Node& joining,
             const std::string& joining_file, std::string process,
             const std::vector<std::string>& plugin_path);
  ~AppletHost();
  AppletHost(const AppletHost&) = delete;
  AppletHost& operator=(const AppletHost&) = delete;

  /// Starts one thread per applet: it announces itself to the coordinator with the bundles it
  /// asks for (`requested: true` ones at first), then runs init() and step() as in the
  /// coordinator, with the coordinator's notifications between steps.
  void start();
  /// Stops the applets' threads (also called by the destructor). The coordinator takes their
  /// bundles when their lease runs out.
  void stop();

  /// The applets the system file puts in `process` (their `process:`).
  static std::vector<std::string> applets_of(const SystemSpec& system, const std::string& process);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace oscar::coordinator
