#pragma once
// What the benchmarks that boot systems share: a keystore for a system file, and a module of a
// registry's state by name.

#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "oscar/process_util.hpp"
#include "oscar/registry/registry_client.hpp"
#include "process.hpp"

namespace oscar::test {

/// A keystore for the system in `file`, made by `oscar security init` in a folder named after
/// `name` (emptied first).
inline std::string make_bench_keystore(const std::string& file, const std::string& name) {
  const auto keystore = temp_path(name + "_keys");
  std::filesystem::remove_all(keystore);
  Process init({sibling_program("oscar-security"), "init", file, "--keystore", keystore},
               keystore + ".log");
  if (init.wait(std::chrono::seconds(60)) != 0) {
    throw std::runtime_error("oscar security init failed:\n" + init.output());
  }
  return keystore;
}

/// The module `name` of `s`, or nullptr.
inline const ModuleEntry* module_of(const SystemState& s, const std::string& name) {
  for (const auto& m : s.modules()) {
    if (m.name() == name) return &m;
  }
  return nullptr;
}

}  // namespace oscar::test
