#pragma once
// Internal: the registry's journal (docs/boot.md, "When the registry dies"), what a registry
// started again after a crash cannot learn from the wire: each module's configuration to
// restore, its restart counters and a restart in progress. One small YAML file, replaced
// whole (temporary file, then rename) so a reader never sees half of one.

#include <optional>
#include <string>
#include <vector>

#include "oscar/time.hpp"

namespace oscar::internal {

/// One module as the registry last knew it. Times are wall-clock (ns since the epoch): they
/// must mean the same to the next registry process.
struct JournalModule {
  std::string name{};
  unsigned incarnation = 0;      ///< the current one, or the failed one a restart replaces
  std::string restore{};         ///< the configuration its next incarnation gets (--restore)
  unsigned restarts = 0;         ///< restarts after failures (`oscar ps`)
  std::vector<Stamp> counted{};  ///< the restarts the restart limit counts, when they were
  std::string last_failure{};    ///< why it failed last
  /// What the registry made of it: "restarting" (a restart is due), "failed" (given up, or
  /// waiting for the operator), "replaced" (its standby took over), else running or on its way.
  std::string status{};
  std::string replaced_by{};       ///< the standby module that takes its place
  bool restart_requested = false;  ///< that restart is an operator's, not a failure's
  Stamp restart_at = 0;            ///< when the restart is due (status "restarting")

  bool operator==(const JournalModule&) const = default;
};

struct RegistryJournal {
  Stamp written = 0;  ///< when it was written
  std::vector<JournalModule> modules{};

  bool operator==(const RegistryJournal&) const = default;

  std::string to_yaml() const;
  /// @throws std::invalid_argument "<file>: <what is wrong>" for text that is not a journal
  /// (torn, garbled, or of another version).
  static RegistryJournal parse(const std::string& text, const std::string& file);

  /// Replaces `file` atomically (`file`.tmp, then rename).
  /// @throws std::runtime_error naming the file and the reason if it cannot be written.
  void write(const std::string& file) const;
  /// The journal in `file`; nothing if there is none.
  /// @throws std::invalid_argument as parse() does.
  static std::optional<RegistryJournal> read(const std::string& file);
};

}  // namespace oscar::internal
