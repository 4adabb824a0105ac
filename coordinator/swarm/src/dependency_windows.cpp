#include "oscar/swarm/dependency_windows.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/topological_sort.hpp>
#include <stdexcept>

namespace oscar::swarm {

namespace {

std::map<std::string, int> index_of(const std::vector<JobSpec>& jobs) {
  std::map<std::string, int> index;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    if (!index.emplace(jobs[i].id, static_cast<int>(i)).second) {
      throw std::invalid_argument(fmt::format("dependent jobs: duplicate job id '{}'", jobs[i].id));
    }
  }
  return index;
}

}  // namespace

std::vector<std::string> topological_order(
    const std::vector<JobSpec>& jobs,
    const std::map<std::string, std::vector<std::string>>& depends) {
  const auto index = index_of(jobs);
  using Graph = boost::adjacency_list<boost::vecS, boost::vecS, boost::directedS>;
  Graph graph(jobs.size());
  for (const auto& [job, deps] : depends) {
    const auto c = index.find(job);
    if (c == index.end()) {
      throw std::invalid_argument(fmt::format("depends: unknown job id '{}'", job));
    }
    for (const auto& d : deps) {
      const auto a = index.find(d);
      if (a == index.end()) {
        throw std::invalid_argument(
            fmt::format("depends: job '{}' depends on unknown job id '{}'", job, d));
      }
      boost::add_edge(a->second, c->second, graph);  // a before c
    }
  }
  std::vector<std::size_t> reversed;
  try {
    boost::topological_sort(graph, std::back_inserter(reversed));
  } catch (const boost::not_a_dag&) {
    throw std::invalid_argument("depends: the dependencies contain a cycle (they must form a DAG)");
  }
  std::vector<std::string> order;
  for (auto it = reversed.rbegin(); it != reversed.rend(); ++it) order.push_back(jobs[*it].id);
  return order;
}

std::map<std::string, ImplicitWindow> implicit_windows(
    const std::vector<JobSpec>& jobs,
    const std::map<std::string, std::vector<std::string>>& depends, double margin,
    const std::map<std::string, double>& fixed) {
  const auto order = topological_order(jobs, depends);
  const auto index = index_of(jobs);
  std::map<std::string, double> t_min, t_max, alpha, beta;
  for (const auto& j : jobs) {
    const auto f = fixed.find(j.id);
    t_min[j.id] = f != fixed.end() ? f->second : j.earliest_start;
    t_max[j.id] = f != fixed.end() ? f->second : j.latest_finish - j.duration;
  }
  std::map<std::string, std::vector<std::string>> dependents;
  for (const auto& [c, deps] : depends) {
    for (const auto& a : deps) dependents[a].push_back(c);
  }
  for (const auto& id : order) {  // eq. 4.10, dependencies first
    const double d = jobs[index.at(id)].duration;
    double m = t_min[id];
    if (auto it = depends.find(id); it != depends.end()) {
      for (const auto& a : it->second) m = std::max(m, alpha[a] + margin);
    }
    alpha[id] = m + d;
  }
  for (auto it = order.rbegin(); it != order.rend(); ++it) {  // eq. 4.11, dependents first
    const double d = jobs[index.at(*it)].duration;
    double m = t_max[*it];
    for (const auto& c : dependents[*it]) m = std::min(m, beta[c] - d - margin);
    beta[*it] = m;
  }
  std::map<std::string, ImplicitWindow> result;
  for (const auto& j : jobs) result[j.id] = {alpha[j.id] - j.duration, beta[j.id]};
  return result;
}

}  // namespace oscar::swarm
