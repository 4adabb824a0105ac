#include "oscar/swarm/scheduler.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <boost/geometry.hpp>
#include <boost/geometry/algorithms/point_on_surface.hpp>
#include <cmath>
#include <random>
#include <stdexcept>

#include "oscar/swarm/dubins_path_finder.hpp"
#include "oscar/swarm/trajectory_planner.hpp"
#include "scheduler_state.hpp"

namespace oscar::swarm {

namespace bg = boost::geometry;

void check_time(double t, const std::string& what) {
  if (!std::isfinite(t)) throw std::invalid_argument(fmt::format("{} must be finite", what));
  if (std::abs(t) > kMaxAbsTime) {
    throw std::invalid_argument(
        fmt::format("{} = {} is beyond ±{} s, where times in double lose sub-nanosecond precision "
                    "(seed §5.3.1)",
                    what, t, kMaxAbsTime));
  }
}

Scheduler::Scheduler(World world, SchedulerSettings settings)
    : world_(std::move(world)), settings_(settings) {
  check_time(settings_.present, "settings.present");
  check_time(settings_.frozen_horizon, "settings.frozen_horizon");
  if (settings_.frozen_horizon < 0)
    throw std::invalid_argument("settings.frozen_horizon must be >= 0");
  if (!std::isfinite(settings_.dependency_margin) || settings_.dependency_margin < 0) {
    throw std::invalid_argument("settings.dependency_margin must be finite and >= 0");
  }
  if (settings_.location_samples < 1) {
    throw std::invalid_argument("settings.location_samples must be >= 1");
  }
  if (!std::isfinite(settings_.wait_threshold) || settings_.wait_threshold < 0) {
    throw std::invalid_argument("settings.wait_threshold must be finite and >= 0");
  }
  for (std::size_t i = 0; i < world_.dynamic_obstacles.size(); ++i) {
    if (world_.dynamic_obstacles[i].trajectory.empty()) {
      throw std::invalid_argument(fmt::format("world.dynamic[{}]: trajectory is empty", i));
    }
    for (const auto& w : world_.dynamic_obstacles[i].trajectory.points()) {
      check_time(w.t, fmt::format("world.dynamic[{}] trajectory time", i));
    }
  }
}

Scheduler::~Scheduler() = default;
Scheduler::Scheduler(Scheduler&&) noexcept = default;
Scheduler& Scheduler::operator=(Scheduler&&) noexcept = default;

Scheduler::NodeState& Scheduler::state(const std::string& id) {
  for (auto& n : nodes_) {
    if (n->spec.id == id) return *n;
  }
  throw std::invalid_argument(fmt::format("unknown node id '{}'", id));
}

const Scheduler::NodeState& Scheduler::state(const std::string& id) const {
  return const_cast<Scheduler*>(this)->state(id);
}

std::vector<std::string> Scheduler::node_ids() const {
  std::vector<std::string> ids;
  for (const auto& n : nodes_) ids.push_back(n->spec.id);
  return ids;
}

const NodeSpec& Scheduler::node(const std::string& id) const { return state(id).spec; }

const Trajectory& Scheduler::trajectory(const std::string& node, bool committed) const {
  const auto& n = state(node);
  return committed ? n.committed : n.working;
}

const std::vector<Job>& Scheduler::jobs(const std::string& node, bool committed) const {
  const auto& n = state(node);
  return committed ? n.committed_jobs : n.working_jobs;
}

Load Scheduler::load(const std::string& node, double t0, double t1) const {
  const auto& n = state(node);
  return compute_load(n.committed, n.committed_jobs, n.spec.max_speed_mps, t0, t1);
}

const SpatialPathFinder& Scheduler::finder(const NodeState& n) const {
  auto& f = finders_[n.spec.radius_m];
  if (!f) {
    std::vector<Polygon> grown;
    // A hair more than the radius so that driving along an inflated edge keeps the distance.
    for (const auto& p : world_.static_obstacles)
      grown.push_back(inflate(p, n.spec.radius_m + 1e-6));
    f = std::make_unique<SpatialPathFinder>(std::move(grown));
  }
  return *f;
}

TrajectoryPlanner::PathFunction Scheduler::path_function(const NodeState& n) const {
  if (n.spec.turning_radius_m <= 0) {
    const SpatialPathFinder* f = &finder(n);
    return [f](const Point& a, const Point& b) { return f->find(a, b); };
  }
  // A node with a minimum turning radius: OMPL's Dubins planner on the same inflated obstacles.
  auto& d = dubins_finders_[{n.spec.radius_m, n.spec.turning_radius_m}];
  if (!d) {
    std::vector<Polygon> grown;
    for (const auto& p : world_.static_obstacles)
      grown.push_back(inflate(p, n.spec.radius_m + 1e-6));
    d = std::make_unique<DubinsPathFinder>(
        std::move(grown), DubinsPathFinder::Settings{n.spec.turning_radius_m, 2000, 8, 0.1});
  }
  const DubinsPathFinder* f = d.get();
  return [f](const Point& a, const Point& b) { return f->find(a, b); };
}

std::vector<MovingObstacle> Scheduler::obstacles_for(const NodeState& n) const {
  std::vector<MovingObstacle> result;
  for (const auto& o : world_.dynamic_obstacles) {
    result.push_back({inflate(o.shape, n.spec.radius_m + 1e-6), o.trajectory});
  }
  auto as_obstacle = [](const Trajectory& t, double r) {
    Trajectory extended = t;
    const auto last = t.points().back();
    if (last.t < kForever) extended.append({last.x, last.y, kForever});
    return MovingObstacle{disc_polygon(r), std::move(extended)};
  };
  for (const auto& other : nodes_) {
    if (other.get() == &n) continue;
    const double r = other->spec.radius_m + n.spec.radius_m + 1e-6;
    // §4.2.7: an open transaction's alternative counts as an obstacle beside the committed one.
    result.push_back(as_obstacle(other->working, r));
    if (other->working.points().size() != other->committed.points().size() ||
        !std::equal(other->working.points().begin(), other->working.points().end(),
                    other->committed.points().begin(), [](const Waypoint& a, const Waypoint& b) {
                      return a.x == b.x && a.y == b.y && a.t == b.t;
                    })) {
      result.push_back(as_obstacle(other->committed, r));
    }
  }
  return result;
}

void Scheduler::add_node(const NodeSpec& spec) {
  const std::string what = fmt::format("node '{}'", spec.id);
  if (spec.id.empty()) throw std::invalid_argument("node: id must not be empty");
  for (const auto& n : nodes_) {
    if (n->spec.id == spec.id) throw std::invalid_argument(what + ": duplicate node id");
  }
  if (!std::isfinite(spec.radius_m) || spec.radius_m < 0) {
    throw std::invalid_argument(what + ": radius must be finite and >= 0");
  }
  if (!std::isfinite(spec.max_speed_mps) || spec.max_speed_mps <= 0) {
    throw std::invalid_argument(what + ": max_speed must be finite and > 0");
  }
  if (!std::isfinite(spec.x) || !std::isfinite(spec.y)) {
    throw std::invalid_argument(what + ": start must be finite");
  }
  check_time(spec.t, what + " start time");
  if (!std::isfinite(spec.turning_radius_m) || spec.turning_radius_m < 0) {
    throw std::invalid_argument(what + ": turning_radius must be finite and >= 0");
  }
  auto n = std::make_unique<NodeState>();
  n->spec = spec;
  n->committed = Trajectory({{spec.x, spec.y, spec.t}});
  n->working = n->committed;
  const Point p(spec.x, spec.y);
  if (!finder(*n).is_free(p)) {
    throw std::invalid_argument(what + ": start lies within radius of a static obstacle");
  }
  TrajectoryPlanner planner(path_function(*n), obstacles_for(*n), {spec.max_speed_mps, 0, 0});
  auto tail = idle_tail(*n, planner, p, spec.t);
  if (!tail) {
    throw std::invalid_argument(what +
                                ": idling at the start collides with a moving obstacle or another "
                                "node, and no free place to get out of the way was found");
  }
  n->committed = *tail;
  n->working = n->committed;
  nodes_.push_back(std::move(n));
}

bool Scheduler::job_exists(const std::string& id) const {
  for (const auto& n : nodes_) {
    for (const auto* list : {&n->working_jobs, &n->committed_jobs}) {
      for (const auto& j : *list) {
        if (j.id == id) return true;
      }
    }
  }
  return false;
}

void Scheduler::validate(const JobSpec& spec, bool allow_existing) const {
  const std::string what = fmt::format("job '{}'", spec.id);
  if (spec.id.empty()) throw std::invalid_argument("job: id must not be empty");
  if (!allow_existing && job_exists(spec.id)) {
    throw std::invalid_argument(what + ": id is already scheduled");
  }
  make_polygon(vertices(spec.area), what + " area");
  check_time(spec.earliest_start, what + " earliest_start");
  check_time(spec.latest_finish, what + " latest_finish");
  if (!std::isfinite(spec.duration) || spec.duration <= 0) {
    throw std::invalid_argument(what + ": duration must be finite and > 0");
  }
  if (spec.latest_finish - spec.earliest_start < spec.duration) {
    throw std::invalid_argument(fmt::format("{}: window [{}, {}] is shorter than the duration {}",
                                            what, spec.earliest_start, spec.latest_finish,
                                            spec.duration));
  }
}

void Scheduler::set_present(double t) {
  check_time(t, "present time");
  if (t < settings_.present) {
    throw std::invalid_argument(
        fmt::format("present time must not go backwards: {} < {}", t, settings_.present));
  }
  settings_.present = t;
}

std::vector<Point> Scheduler::sample_locations(const Polygon& area) {
  // First a point inside the area (its centroid if inside), then uniform samples (seed §4.2.1, Ort:
  // any P ∈ A ∩ S will do). The static obstacles are checked per node with its radius.
  std::vector<Point> result;
  Point c;
  bg::centroid(area, c);
  if (!strictly_inside(c, area)) bg::point_on_surface(area, c);
  result.push_back(c);
  const auto box = bg::return_envelope<bg::model::box<Point>>(area);
  std::mt19937 rng(settings_.seed * 7919u + sample_counter_++);
  std::uniform_real_distribution<double> ux(box.min_corner().x(), box.max_corner().x());
  std::uniform_real_distribution<double> uy(box.min_corner().y(), box.max_corner().y());
  for (int tries = 0; static_cast<int>(result.size()) < settings_.location_samples && tries < 1000;
       ++tries) {
    const Point p(ux(rng), uy(rng));
    bool blocked = false;
    for (const auto& o : world_.static_obstacles) blocked = blocked || strictly_inside(p, o);
    if (strictly_inside(p, area) && !blocked) result.push_back(p);
  }
  return result;
}

bool Scheduler::locked_by_other(const NodeState& n, TransactionId tx, double lo, double hi) const {
  for (const auto& l : n.locks) {
    if (l.tx != tx && lo < l.hi && l.lo < hi) return true;
  }
  return false;
}

void Scheduler::record(TransactionId tx, NodeState& n, double lo, double hi) {
  auto& changes = transactions_[tx];
  auto it = changes.find(n.spec.id);
  if (it == changes.end()) {
    changes[n.spec.id] = Change{lo, hi, {}, {}};
    n.locks.push_back({tx, lo, hi});
    return;
  }
  it->second.lo = std::min(it->second.lo, lo);
  it->second.hi = std::max(it->second.hi, hi);
  for (auto& l : n.locks) {
    if (l.tx == tx) l = {tx, it->second.lo, it->second.hi};
  }
}

TransactionId Scheduler::open_transaction() {
  const TransactionId id = next_transaction_++;
  transactions_[id];
  return id;
}

std::vector<TransactionId> Scheduler::open_transactions() const {
  std::vector<TransactionId> ids;
  for (const auto& [id, changes] : transactions_) ids.push_back(id);
  return ids;
}

void Scheduler::finish(TransactionId tx, const std::string& node, bool commit) {
  auto it = transactions_.find(tx);
  if (it == transactions_.end()) {
    throw std::invalid_argument(fmt::format("unknown or finished transaction {}", tx));
  }
  auto& changes = it->second;
  if (!node.empty()) {
    state(node);  // throws on an unknown node
  }
  for (auto c = changes.begin(); c != changes.end();) {
    if (!node.empty() && c->first != node) {
      ++c;
      continue;
    }
    auto& n = state(c->first);
    const Change& ch = c->second;
    auto by_start = [](const Job& a, const Job& b) { return a.start < b.start; };
    if (commit) {
      n.committed = n.committed.spliced(n.working, ch.lo, ch.hi);
      for (const auto& r : ch.removed) {
        std::erase_if(n.committed_jobs, [&](const Job& j) { return j.id == r.id; });
      }
      for (const auto& id : ch.added) {
        for (const auto& j : n.working_jobs) {
          if (j.id == id) n.committed_jobs.push_back(j);
        }
      }
      std::sort(n.committed_jobs.begin(), n.committed_jobs.end(), by_start);
    } else {
      n.working = n.working.spliced(n.committed, ch.lo, ch.hi);
      for (const auto& id : ch.added) {
        std::erase_if(n.working_jobs, [&](const Job& j) { return j.id == id; });
      }
      for (const auto& r : ch.removed) n.working_jobs.push_back(r);
      std::sort(n.working_jobs.begin(), n.working_jobs.end(), by_start);
    }
    std::erase_if(n.locks, [&](const NodeState::Lock& l) { return l.tx == tx; });
    c = changes.erase(c);
  }
  if (changes.empty() || node.empty()) transactions_.erase(it);
}

void Scheduler::commit(TransactionId id, const std::string& node) { finish(id, node, true); }
void Scheduler::abort(TransactionId id, const std::string& node) { finish(id, node, false); }

}  // namespace oscar::swarm
