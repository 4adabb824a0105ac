// oscar bench swarm [--json]: the dimensions of seed 002 ch. 6.2 (success and failure case each)
// and an end-to-end run. Prints figures; decides nothing by time.
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>

#include "oscar/swarm/forbidden_regions.hpp"
#include "oscar/swarm/scheduler.hpp"
#include "oscar/swarm/trajectory_planner.hpp"
#ifdef OSCAR_SWARM_LIVE
#include "live_bench.hpp"
#endif

using namespace oscar::swarm;

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

Polygon circle(double r, int n) {
  std::vector<Point> pts;
  for (int k = 0; k < n; ++k)
    pts.emplace_back(r * std::cos(2 * M_PI * k / n), r * std::sin(2 * M_PI * k / n));
  return make_polygon(pts, "circle");
}

Polygon square(double cx, double cy, double h) {
  return make_polygon({{cx - h, cy - h}, {cx + h, cy - h}, {cx + h, cy + h}, {cx - h, cy + h}},
                      "square");
}

struct Timed {
  double ms;
  bool ok;
};

// Times only `run`, not `setup` (building a world of n nodes is not part of scheduling a job).
template <typename Setup, typename Run>
Timed timed(Setup setup, Run run) {
  auto state = setup();
  const auto t0 = Clock::now();
  const bool ok = run(state);
  return {ms_since(t0), ok};
}

// Minimum of `repeat` runs (seed §6.2: the smallest of 5-20 measurements).
double measure(int repeat, const std::function<Timed()>& f, bool& ok) {
  double best = 1e300;
  for (int i = 0; i < repeat; ++i) {
    const Timed t = f();
    ok = t.ok;
    best = std::min(best, t.ms);
  }
  return best;
}

struct Row {
  int n;
  double ms;
  bool ok;
};

// Velocity planning along a 100 m path with `obstacles` crossing it, each with `vertices` corners
// and `segments` trajectory segments, path of `path_segments` segments; `block` parks one more
// obstacle on the goal for good (the failure case).
Timed plan_velocity(int obstacles, int vertices, int segments, int path_segments, bool block) {
  std::vector<Point> path;
  for (int i = 0; i <= path_segments; ++i) {
    path.emplace_back(100.0 * i / path_segments, (i % 2) * (path_segments > 1 ? 2.0 : 0.0));
  }
  std::vector<MovingObstacle> obs;
  for (int k = 0; k < obstacles; ++k) {
    std::vector<Waypoint> w;
    const double x = 100.0 * (k + 0.5) / obstacles;
    for (int j = 0; j <= segments; ++j)
      w.push_back({x, (j % 2) ? 10.0 : -10.0, 3.0 * k + 20.0 * j / segments});
    obs.push_back({circle(0.8, vertices), Trajectory(w)});
  }
  if (block) obs.push_back({square(0, 0, 1), Trajectory({{100, 0, 0}, {100, 0, kForever}})});
  SpatialPathFinder none({});
  TrajectoryPlanner planner([&none](const Point& a, const Point& b) { return none.find(a, b); },
                            std::move(obs), {2.0, 0, 0});
  const auto t0 = Clock::now();
  const bool ok = planner.earliest_arrival(path, 0, 1000).has_value();
  return {ms_since(t0), ok};
}

// n nodes on a circle of radius 20 around a job at the centre (seed Abb. 6.9); in the failure case
// an obstacle stands on the centre during the whole window.
Scheduler circle_world(int nodes, bool block, int jobs_per_node = 0) {
  World w;
  if (block) w.dynamic_obstacles.push_back({square(0, 0, 2), Trajectory({{0, 0, 0}, {0, 0, 500}})});
  Scheduler s(std::move(w), {.location_samples = 3});
  for (int i = 0; i < nodes; ++i) {
    const double a = 2 * M_PI * i / nodes;
    s.add_node({fmt::format("n{}", i), 0.2, 1, 20 * std::cos(a), 20 * std::sin(a), 0, 0});
  }
  // Pauses: jobs of node 0 every 10 s at its own place.
  for (int j = 0; j < jobs_per_node; ++j) {
    const double t = 1000 + 10.0 * j;
    auto r = s.schedule(JobSpec{fmt::format("busy{}", j), square(20, 0, 0.05), t, t + 2, 2});
    if (r.ok) s.commit(r.transaction);
  }
  return s;
}

// `nodes` nodes and `jobs` jobs (each committed) in a 200 m square with `obstacles` static
// squares of 1-3 m at random places: how static obstacles scale the whole scheduling.
struct StaticRun {
  double seconds;
  int scheduled;
};
StaticRun static_world_run(int obstacles, int nodes, int jobs) {
  std::mt19937 rng(7);
  auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  World w;
  for (int i = 0; i < obstacles; ++i)
    w.static_obstacles.push_back(square(uni(5, 195), uni(5, 195), uni(0.5, 1.5)));
  Scheduler s(std::move(w), {.frozen_horizon = 1, .location_samples = 3});
  for (int added = 0, tries = 0; added < nodes && tries < 100 * nodes; ++tries) {
    try {
      s.add_node({fmt::format("n{}", added), 0.3, 1.0, uni(0, 200), uni(0, 200), 0, 0});
      ++added;
    } catch (const std::invalid_argument&) {
    }
  }
  int scheduled = 0;
  const auto t0 = Clock::now();
  for (int j = 0; j < jobs; ++j) {
    const double x = uni(5, 195), y = uni(5, 195), t = uni(0, 2500), d = uni(5, 30);
    const auto r = s.schedule(JobSpec{fmt::format("J{}", j), square(x, y, 2), t, t + d + 300, d});
    if (r.ok) {
      s.commit(r.transaction);
      ++scheduled;
    }
  }
  return {ms_since(t0) / 1000, scheduled};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"oscar bench swarm: swarm planner figures (seed 002 ch. 6)"};
  bool json = false;
  int repeat = 5, e2e_nodes = 100, e2e_obstacles = 50, e2e_jobs = 1000;
  double max_seconds = 120;
  int static_max = 400;
  app.add_flag("--json", json, "print JSON instead of tables");
  app.add_option("--repeat", repeat, "measurements per point (the minimum is reported)");
  app.add_option("--nodes", e2e_nodes, "end-to-end: nodes");
  app.add_option("--obstacles", e2e_obstacles, "end-to-end: moving obstacles");
  app.add_option("--jobs", e2e_jobs, "end-to-end: jobs");
  app.add_option("--max-seconds", max_seconds, "end-to-end: stop scheduling after this long");
  app.add_option("--static-max", static_max, "static obstacles series: up to this many");
#ifdef OSCAR_SWARM_LIVE
  bool live = false;
  std::vector<int> live_robots{10, 50};
  double live_seconds = 60, live_rate = 0;
  app.add_flag("--live", live,
               "instead: boot robots, the coordinator and the safety monitor on this host and "
               "submit jobs at a steady rate (submit -> committed, jobs done, NAKs, violations)");
  app.add_option("--robots", live_robots, "--live: robot counts to run, in turn")->delimiter(',');
  app.add_option("--seconds", live_seconds, "--live: how long jobs are submitted");
  app.add_option("--rate", live_rate, "--live: jobs per second (default: robots / 5)");
#endif
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);

  nlohmann::json doc;
#ifdef OSCAR_SWARM_LIVE
  if (live) {
    doc["live"] = nlohmann::json::array();
    for (int n : live_robots) {
      auto r = oscar::bench::run_live(n, live_seconds, live_rate > 0 ? live_rate : n / 5.0);
      if (!json) {
        fmt::print(
            "live: {} robots, {} jobs submitted, {} committed, {} done in their window, submit -> "
            "committed p50 {:.1f} ms p99 {:.1f} ms, {} NAKs, {} timeouts, {} re-plans, {} safety "
            "violations, coordinator CPU {:.1f} %\n",
            r["robots"].get<int>(), r["jobs_submitted"].get<int>(), r["jobs_committed"].get<int>(),
            r["jobs_done_in_window"].get<int>(), r["submit_to_commit_ms_p50"].get<double>(),
            r["submit_to_commit_ms_p99"].get<double>(), r["naks"].get<long>(),
            r["timeouts"].get<long>(), r["replans"].get<long>(), r["safety_violations"].get<long>(),
            r["coordinator_cpu_percent"].get<double>());
      }
      doc["live"].push_back(std::move(r));
    }
    if (json) std::cout << doc.dump(2) << "\n";
    return 0;
  }
#endif
  auto series = [&](const std::string& name, const std::vector<int>& sizes,
                    const std::function<Timed(int, bool)>& f) {
    // One array per dimension as the issue names it; each entry says which case it measures.
    doc["series"][name] = nlohmann::json::array();
    for (bool fail : {false, true}) {
      const char* which = fail ? "failure" : "success";
      if (!json) {
        fmt::print("\n{:<34} {:>6} {:>11} {:>8}\n", name + " (" + which + ")", "n", "ms (min)",
                   "planned");
      }
      for (int n : sizes) {
        bool ok = false;
        const double ms = measure(
            repeat, [&] { return f(n, fail); }, ok);
        doc["series"][name].push_back({{"n", n}, {"ms", ms}, {"case", which}, {"ok", ok}});
        if (!json) fmt::print("{:<34} {:>6} {:>11.3f} {:>8}\n", "", n, ms, ok ? "yes" : "no");
      }
    }
  };
  series("moving_obstacles", {1, 2, 4, 8, 16, 32},
         [](int n, bool f) { return plan_velocity(n, 8, 1, 1, f); });
  series("obstacle_detail", {4, 8, 16, 32, 64},
         [](int n, bool f) { return plan_velocity(4, n, 1, 1, f); });
  series("obstacle_trajectory_segments", {1, 2, 4, 8, 16, 32},
         [](int n, bool f) { return plan_velocity(1, 8, n, 1, f); });
  series("path_segments", {1, 2, 4, 8, 16, 32},
         [](int n, bool f) { return plan_velocity(2, 8, 4, n, f); });
  auto centre_job = [](Scheduler& s) {
    return s.schedule(JobSpec{"J", square(0, 0, 1), 50, 200, 10}).ok;
  };
  series("nodes", {10, 25, 50, 100},
         [&](int n, bool f) { return timed([&] { return circle_world(n, f); }, centre_job); });
  series("slots", {5, 10, 20, 40},
         [&](int n, bool f) { return timed([&] { return circle_world(2, f, n); }, centre_job); });
  series("periodic_jobs", {2, 4, 8, 16}, [](int n, bool f) {
    World w;
    if (f)
      w.dynamic_obstacles.push_back(
          {square(0, 0, 2), Trajectory({{5, 0, 20.0 * n - 15}, {5, 0, 20.0 * n + 40}})});
    Scheduler s(std::move(w), {.location_samples = 3});
    s.add_node({"n", 0.2, 1, 0, 0, 0, 0});
    PeriodicSpec p{{}, square(5, 0, 1), true, 10, 20, 5};
    for (int i = 0; i < n; ++i) p.ids.push_back(fmt::format("P{}", i));
    const auto t0 = Clock::now();
    const bool ok = s.schedule(p).ok;
    return Timed{ms_since(t0), ok};
  });
  series("dependent_jobs", {2, 4, 8, 16}, [](int n, bool f) {
    World w;
    if (f)
      w.dynamic_obstacles.push_back(
          {square(0, 0, 2), Trajectory({{3.0 * n, 0, 0}, {3.0 * n, 0, 2000}})});
    Scheduler s(std::move(w), {.location_samples = 3});
    s.add_node({"n", 0.2, 1, 0, -5, 0, 0});
    DependentSpec d;
    for (int i = 1; i <= n; ++i) {
      d.jobs.push_back({fmt::format("D{}", i), square(3.0 * i, 0, 0.5), 0, 1000, 5});
      if (i > 1) d.depends[fmt::format("D{}", i)] = {fmt::format("D{}", i - 1)};
    }
    const auto t0 = Clock::now();
    const bool ok = s.schedule(d).ok;
    return Timed{ms_since(t0), ok};
  });

  // Static obstacles: 20 nodes and 100 jobs among more and more static squares (one run each).
  doc["series"]["static_obstacles"] = nlohmann::json::array();
  if (!json)
    fmt::print("\n{:<34} {:>6} {:>11} {:>9}\n", "static_obstacles (20 nodes, 100 jobs)", "n",
               "s total", "scheduled");
  for (int n : {25, 50, 100, 200, 400}) {
    if (n > static_max) break;
    const auto r = static_world_run(n, 20, 100);
    doc["series"]["static_obstacles"].push_back(
        {{"n", n}, {"seconds", r.seconds}, {"scheduled", r.scheduled}});
    if (!json) fmt::print("{:<34} {:>6} {:>11.3f} {:>9}\n", "", n, r.seconds, r.scheduled);
  }

  // End to end: a 200 m square, random moving obstacles and jobs, every success committed.
  {
    std::mt19937 rng(42);
    auto uni = [&](double a, double b) {
      return std::uniform_real_distribution<double>(a, b)(rng);
    };
    World w;
    for (int i = 0; i < 4; ++i)
      w.static_obstacles.push_back(square(uni(30, 170), uni(30, 170), uni(3, 8)));
    for (int i = 0; i < e2e_obstacles; ++i) {
      std::vector<Waypoint> pts;
      double t = uni(0, 100);
      for (int k = 0; k < 4; ++k) {
        pts.push_back({uni(0, 200), uni(0, 200), t});
        t += uni(200, 800);
      }
      w.dynamic_obstacles.push_back({square(0, 0, 1), Trajectory(pts)});
    }
    Scheduler s(std::move(w), {.frozen_horizon = 1, .location_samples = 3});
    int added = 0;
    for (int tries = 0; added < e2e_nodes && tries < 100 * e2e_nodes; ++tries) {
      try {
        s.add_node({fmt::format("n{}", added), 0.3, 1.0, uni(0, 200), uni(0, 200), 0, 0});
        ++added;
      } catch (const std::invalid_argument&) {
      }
    }
    std::vector<double> times;
    int scheduled = 0;
    const auto start = Clock::now();
    for (int j = 0; j < e2e_jobs && ms_since(start) < max_seconds * 1000; ++j) {
      const double x = uni(5, 195), y = uni(5, 195), t = uni(0, 2500), d = uni(5, 30);
      JobSpec spec{fmt::format("J{}", j), square(x, y, 2), t, t + d + uni(30, 300), d};
      const auto t0 = Clock::now();
      const auto r = s.schedule(spec);
      if (r.ok) {
        s.commit(r.transaction);
        ++scheduled;
      }
      times.push_back(ms_since(t0));
    }
    std::vector<double> sorted = times;
    std::sort(sorted.begin(), sorted.end());
    auto pct = [&](double p) {
      return sorted.empty()
                 ? 0.0
                 : sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(p * sorted.size()))];
    };
    doc["e2e"] = {{"nodes", added},
                  {"obstacles", e2e_obstacles},
                  {"jobs", times.size()},
                  {"scheduled", scheduled},
                  {"rejected", static_cast<int>(times.size()) - scheduled},
                  {"ms_p50", pct(0.5)},
                  {"ms_p99", pct(0.99)},
                  {"ms_max", sorted.empty() ? 0 : sorted.back()},
                  {"seconds_total", ms_since(start) / 1000}};
    if (!json) {
      fmt::print("\nend to end: {} nodes, {} moving obstacles, {} jobs tried\n", added,
                 e2e_obstacles, times.size());
      fmt::print(
          "scheduled {}, rejected {}, per job p50 {:.2f} ms, p99 {:.2f} ms, max {:.2f} ms, total "
          "{:.1f} s\n",
          scheduled, static_cast<int>(times.size()) - scheduled, pct(0.5), pct(0.99),
          sorted.empty() ? 0 : sorted.back(), ms_since(start) / 1000);
    }
  }
  if (json) std::cout << doc.dump(2) << "\n";
  return 0;
}
