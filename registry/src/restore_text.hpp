#pragma once
// Internal: what a module's next incarnation gets back (`oscar-run --restore`), made from its
// last announcement, and a cache of it for the registry, which puts every running module's into
// its journal on each state it publishes.

#include <string>

#include <oscar/config.h>

namespace oscar::internal {

/// The coordinator's changes a module's announcement shows (modes, stub, parameters, wiring),
/// as the YAML flow map `oscar-run --restore` takes.
std::string restore_text(const ModuleState& last);

/// restore_text() of a module's announcements, made again only when what it reads changed.
/// A module announces itself every second with new counters, and the registry puts every
/// running module's restore text into its journal on each state it publishes: made each time
/// (a YAML emitter and a parse of each kernel's parameters), that was a third of the registry's
/// CPU samples while a system of 60 modules booted, the square of the modules
/// (docs/benchmarks.md).
class RestoreTextCache {
 public:
  const std::string& of(const ModuleState& last);

 private:
  std::string source_;  // the fields restore_text() reads, as last made
  std::string text_;
};

}  // namespace oscar::internal
