#pragma once
/// @file Where `oscar boot` leaves word of the systems it runs on this machine, so that the
/// tools (`oscar ps`, `topics`, `shutdown`, ...) find a running system without being told its
/// domain, and a second boot on a busy domain is refused. One small JSON file per domain in
/// $OSCAR_SYSTEMS_DIR (default /tmp/oscar/systems), removed when boot ends; a record whose boot
/// process is gone (killed with -9) is ignored and cleaned away by the next reader.

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace oscar {

class DdsParticipant;

struct RunningSystem {
  int domain = 0;
  std::string system;                 ///< the system's name
  std::string file;                   ///< the system file, absolute
  std::string log_dir;                ///< where its processes write their output
  std::string keystore{};             ///< its DDS Security keystore, absolute; "" for none
  pid_t boot_pid = 0;                 ///< the `oscar boot` that runs it
  long long started = 0;              ///< seconds since the epoch
  long long boot_started_ticks = -1;  ///< when boot_pid started (pids are reused); set on record

  /// "landmarks (domain 43, config/landmarks-1host.yaml, boot pid 1234)".
  std::string describe() const;
};

/// The folder of the records: $OSCAR_SYSTEMS_DIR, else /tmp/oscar/systems.
std::string running_systems_dir();

/// The systems booted on this machine whose boot still runs, by domain.
std::vector<RunningSystem> running_systems();

/// The running system on `domain`, if this machine has one.
std::optional<RunningSystem> running_system(int domain);

/// True for the participant name of a process that belongs to a running system: the registry
/// ("oscar-registry"), a monitor ("oscar-monitor:<host>") or a module ("oscar:<module>"). Tools
/// and boot have names of their own ("oscar-ps", "oscar-boot", ...).
bool is_system_member(const std::string& participant_name);

/// The processes of other systems that `participant` sees on its domain now, by system, for an
/// error: "the system 'busy' (boot pid 1234 on host1): oscar-registry, oscar:src; processes
/// started by hand: oscar:cam"; "" if none. They are the members (is_system_member) that belong
/// to another booted system than this process ($OSCAR_SYSTEM_INSTANCE, which boot sets for every
/// process it starts). A process started by hand belongs to none: to a booted system it is
/// another system's, and the other way round.
std::string other_systems_on_domain(const DdsParticipant& participant);

/// other_systems_on_domain() for a refusal, once it names a registry (up to 3 s): the other
/// system's registry may show a while after its first process (a loaded machine), and the
/// refusal is worth the wait for a list that names the system's core.
std::string other_systems_in_full(const DdsParticipant& participant);

/// "domain 7 is in use by <others>; stop it (oscar shutdown -d 7) or boot on another domain
/// (--domain N)", with `others` from other_systems_on_domain().
std::string domain_in_use(int domain, const std::string& others);

/// How long a new participant looks for another system's processes before its system starts
/// any. On the development machine a new participant saw the first of a running five-module
/// system's eight participants after 2-23 ms and all of them after 18-191 ms (docs/boot.md); one
/// is enough to refuse. Boot looks this long before it starts the registry, and the registry
/// (its participant this old at least) once more before the first module.
inline constexpr std::chrono::milliseconds kDiscoveryWindow{400};

/// Holds the record of one booted system while it lives (boot keeps one for its run).
class RunningSystemRecord {
 public:
  /// @throws std::runtime_error if another live boot holds the domain (naming it), or if the
  ///         record cannot be written.
  explicit RunningSystemRecord(const RunningSystem& system);
  ~RunningSystemRecord();
  RunningSystemRecord(const RunningSystemRecord&) = delete;
  RunningSystemRecord& operator=(const RunningSystemRecord&) = delete;

 private:
  std::string path_;
};

}  // namespace oscar
