#include "start_order.hpp"

#include <map>
#include <set>
#include <string>

namespace oscar::internal {

std::vector<std::vector<std::size_t>> producers_launched_first(const SystemSpec& system) {
  const auto n = system.modules.size();
  std::map<std::string, std::size_t> module_of_kernel;
  for (std::size_t i = 0; i < n; ++i) {
    for (const auto& k : system.modules[i].spec.kernels) module_of_kernel[k.name] = i;
  }
  // producers[c]: the other modules whose outputs module c reads.
  std::vector<std::set<std::size_t>> producers(n);
  for (std::size_t c = 0; c < n; ++c) {
    for (const auto& k : system.modules[c].spec.kernels) {
      for (const auto& [channel, wire] : k.inputs) {
        const auto kernel = wire.source.substr(0, wire.source.find('/'));
        const auto p = module_of_kernel.find(kernel);
        if (p != module_of_kernel.end() && p->second != c) producers[c].insert(p->second);
      }
    }
  }
  // Kahn's order, taking the first module in file order whose producers are all placed; what a
  // cycle leaves over follows in file order.
  std::vector<std::size_t> rank(n, n);
  std::size_t placed = 0;
  for (bool progress = true; progress;) {
    progress = false;
    for (std::size_t i = 0; i < n; ++i) {
      if (rank[i] != n) continue;
      bool ready = true;
      for (auto p : producers[i]) ready = ready && rank[p] != n;
      if (ready) {
        rank[i] = placed++;
        progress = true;
        break;
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (rank[i] == n) rank[i] = placed++;
  }
  std::vector<std::vector<std::size_t>> first(n);
  for (std::size_t c = 0; c < n; ++c) {
    for (auto p : producers[c]) {
      if (rank[p] < rank[c]) first[c].push_back(p);
    }
  }
  return first;
}

}  // namespace oscar::internal
