#pragma once
// The registry's record of one module (internal to Registry).

#include <string>
#include <vector>

#include "oscar/registry/registry.hpp"
#include "registry_journal.hpp"
#include "restart_budget.hpp"
#include "restore_text.hpp"

namespace oscar {

struct Registry::Tracked {
  const SystemModule* spec = nullptr;
  // At boot it is launched only once these (the producers of its inputs) were: see start_order.hpp.
  std::vector<const Tracked*> launched_after;
  // waiting | starting | running | failed | restarting | replaced | standby | stopped
  std::string status;
  unsigned incarnation = 0;  // 0: never started
  long pid = 0;
  long launched_by = 0;            // pid of the monitor that started the current incarnation
  unsigned restarts = 0;           // after failures, all of them (`oscar ps`)
  internal::RestartBudget budget;  // the restarts after failures the restart limit counts
  bool restart_requested = false;  // the pending restart is an operator's, not a failure's
  std::string last_failure;
  bool process_gone = true;  // the current incarnation's process is known to have ended
  bool suspended = false;    // the registry suspended it and has not resumed it yet
  bool held = false;         // under gdbserver, its heartbeat lapsed (said once per lapse)
  Clock::time_point restart_at{};
  Clock::time_point running_since{};
  std::string replaced_by;  // set when a replacement takes over
  ModuleState state;        // the last announcement of the current incarnation
  bool has_state = false;
  // What the next incarnation gets back (oscar-run --restore): the configuration of the last
  // one, kept when it ended (take_down), or read from the journal by a recovering registry.
  std::string restore;
  internal::RestoreTextCache restore_of_state;  // what `state` would give back (restore_text)
  internal::JournalModule journaled{};          // what the journal says of it now
  double cues_per_s = 0;
  Clock::time_point rate_since{};
  std::uint64_t rate_published = 0;
};

}  // namespace oscar
