#include "oscar/swarm/scheduler.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "oscar/swarm/dubins_path_finder.hpp"
#include "oscar/swarm/trajectory_planner.hpp"
#include "scheduler_state.hpp"

namespace oscar::swarm {

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
  check_world(world_);
}

void Scheduler::check_world(const World& world) {
  for (std::size_t i = 0; i < world.dynamic_obstacles.size(); ++i) {
    if (world.dynamic_obstacles[i].trajectory.empty()) {
      throw std::invalid_argument(fmt::format("world.dynamic[{}]: trajectory is empty", i));
    }
    for (const auto& w : world.dynamic_obstacles[i].trajectory.points()) {
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
        std::move(grown),
        DubinsPathFinder::Settings{n.spec.turning_radius_m, 2000, 8, 0.1, settings_.seed});
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

void Scheduler::check_node_spec(const NodeSpec& spec) const {
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
}

void Scheduler::add_node(const NodeSpec& spec) {
  const std::string what = fmt::format("node '{}'", spec.id);
  check_node_spec(spec);
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

namespace {
// A committed plan crossed the wire: places agree to the robots' own tolerance, times to what ns
// on the wire and seconds from another epoch keep.
constexpr double kCommittedPlaceTolerance = 0.01;  // m
constexpr double kCommittedTimeTolerance = 1e-6;   // s

std::string place_text(const Point& p) { return fmt::format("({:.3f}, {:.3f})", p.x(), p.y()); }
}  // namespace

void Scheduler::add_node(const NodeSpec& spec, const Trajectory& committed, std::vector<Job> jobs) {
  check_node_spec(spec);
  check_committed(spec, committed, jobs);
  auto n = std::make_unique<NodeState>();
  n->spec = spec;
  if (!finder(*n).is_free(Point(spec.x, spec.y))) {
    throw std::invalid_argument(
        fmt::format("node '{}': where it is lies within radius of a static obstacle", spec.id));
  }
  n->committed = committed;
  n->working = committed;
  n->committed_jobs = std::move(jobs);
  n->working_jobs = n->committed_jobs;
  nodes_.push_back(std::move(n));
}

// The rules of add_node with a committed plan; sorts the jobs by start and sets their node.
void Scheduler::check_committed(const NodeSpec& spec, const Trajectory& committed,
                                std::vector<Job>& jobs) const {
  const std::string what = fmt::format("node '{}'", spec.id);
  if (committed.empty()) throw std::invalid_argument(what + ": its committed trajectory is empty");
  for (const auto& w : committed.points()) check_time(w.t, what + " committed trajectory time");
  if (committed.start_time() > spec.t) {
    throw std::invalid_argument(
        fmt::format("{}: its committed trajectory starts at {}, after the node's time {}: it must "
                    "hold where the node is then",
                    what, committed.start_time(), spec.t));
  }
  const Point here(spec.x, spec.y);
  if (const Point p = committed.position_at(spec.t); distance(p, here) > kCommittedPlaceTolerance) {
    throw std::invalid_argument(fmt::format(
        "{}: its committed trajectory has it at {} at {}, not where it is, {} (tolerance {} m)",
        what, place_text(p), spec.t, place_text(here), kCommittedPlaceTolerance));
  }
  std::sort(jobs.begin(), jobs.end(), [](const Job& a, const Job& b) { return a.start < b.start; });
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    Job& j = jobs[i];
    const std::string job_what = fmt::format("{}: committed job '{}'", what, j.id);
    if (j.spec.id != j.id) {
      throw std::invalid_argument(fmt::format("{}: its spec names job '{}'", job_what, j.spec.id));
    }
    if (!j.node.empty() && j.node != spec.id) {
      throw std::invalid_argument(fmt::format("{} is scheduled on node '{}'", job_what, j.node));
    }
    j.node = spec.id;
    validate(j.spec, false);
    if (!std::isfinite(j.x) || !std::isfinite(j.y)) {
      throw std::invalid_argument(job_what + ": its place must be finite");
    }
    check_time(j.start, job_what + " start");
    if (!std::isfinite(j.duration) || j.duration <= 0) {
      throw std::invalid_argument(job_what + ": duration must be finite and > 0");
    }
    if (j.end() < spec.t) {
      throw std::invalid_argument(fmt::format(
          "{}: it ended at {}, before the node's time {}: only jobs not yet done are committed",
          job_what, j.end(), spec.t));
    }
    if (j.start < j.spec.earliest_start - kCommittedTimeTolerance ||
        j.end() > j.spec.latest_finish + kCommittedTimeTolerance) {
      throw std::invalid_argument(fmt::format("{}: [{}, {}] lies outside its window [{}, {}]",
                                              job_what, j.start, j.end(), j.spec.earliest_start,
                                              j.spec.latest_finish));
    }
    if (i > 0 && j.start < jobs[i - 1].end() - kCommittedTimeTolerance) {
      throw std::invalid_argument(fmt::format("{}: it starts at {}, before job '{}' ends at {}",
                                              job_what, j.start, jobs[i - 1].id,
                                              jobs[i - 1].end()));
    }
    for (std::size_t k = 0; k < i; ++k) {
      if (jobs[k].id == j.id) throw std::invalid_argument(job_what + ": duplicate job id");
    }
    // The node stands at the job's place while the job lasts: at its start, its end and every
    // waypoint between (the trajectory is piecewise linear).
    std::vector<double> times{j.start, j.end()};
    for (const auto& w : committed.points()) {
      if (w.t > j.start && w.t < j.end()) times.push_back(w.t);
    }
    for (const double t : times) {
      if (const Point p = committed.position_at(t);
          distance(p, j.location()) > kCommittedPlaceTolerance) {
        throw std::invalid_argument(fmt::format(
            "{}: the committed trajectory has the node at {} at {}, not at the job's place {} "
            "while the job lasts [{}, {}] (tolerance {} m)",
            job_what, place_text(p), t, place_text(j.location()), j.start, j.end(),
            kCommittedPlaceTolerance));
      }
    }
  }
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
  if (!allow_existing && lost_.contains(spec.id)) {
    throw std::invalid_argument(what +
                                ": id is in use by a set member whose node broke down (it waits "
                                "to be placed again within its set)");
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

bool Scheduler::locked_by_other(const NodeState& n, TransactionId tx, double lo, double hi) const {
  for (const auto& l : n.locks) {
    if (l.tx != tx && lo < l.section.hi && l.section.lo < hi) return true;
  }
  return false;
}

void Scheduler::record(TransactionId tx, NodeState& n, double lo, double hi) {
  // The transaction's sections stay disjoint: a new one swallows only its own overlapping ones, so
  // what lies between two sections (another transaction's open change) is never spliced over.
  auto& sections = transactions_.at(tx).changes[n.spec.id].sections;
  Section merged{lo, hi};
  for (bool grew = true; grew;) {
    grew = false;
    std::erase_if(sections, [&](const Section& s) {
      if (s.hi < merged.lo || merged.hi < s.lo) return false;
      merged = {std::min(merged.lo, s.lo), std::max(merged.hi, s.hi)};
      grew = true;
      return true;
    });
  }
  sections.push_back(merged);
  std::erase_if(n.locks, [&](const NodeState::Lock& l) { return l.tx == tx; });
  for (const auto& s : sections) n.locks.push_back({tx, s});
}

TransactionId Scheduler::open_transaction(bool atomic, std::string what) {
  const TransactionId id = next_transaction_++;
  transactions_[id] = Transaction{{}, atomic, std::move(what), {}, {}};
  return id;
}

std::vector<TransactionId> Scheduler::open_transactions() const {
  std::vector<TransactionId> ids;
  for (const auto& [id, tx] : transactions_) ids.push_back(id);
  return ids;
}

const Scheduler::JobSet* Scheduler::set_of(const std::string& job_id) const {
  const auto it = sets_.find(job_id);
  return it == sets_.end() ? nullptr : it->second.get();
}

void Scheduler::keep_as_set(JobSet set, const std::vector<Job>& jobs) {
  set.ids.clear();
  for (const auto& j : jobs) set.ids.push_back(j.id);
  const auto kept = std::make_shared<const JobSet>(std::move(set));
  for (const auto& j : jobs) sets_[j.id] = kept;
}

std::string Scheduler::set_name(const std::string& job_id) const {
  const JobSet* set = set_of(job_id);
  return set ? set->what : "";
}

const Job* Scheduler::working_job(const std::string& id) const {
  for (const auto& n : nodes_) {
    for (const auto& j : n->working_jobs) {
      if (j.id == id) return &j;
    }
  }
  return nullptr;
}

void Scheduler::finish(TransactionId tx, const std::string& node, bool commit) {
  auto it = transactions_.find(tx);
  if (it == transactions_.end()) {
    throw std::invalid_argument(fmt::format("unknown or finished transaction {}", tx));
  }
  auto& changes = it->second.changes;
  if (!node.empty()) {
    state(node);  // throws on an unknown node
    if (it->second.atomic && changes.size() > 1) {
      throw std::invalid_argument(fmt::format(
          "transaction {} ({}) changes {} nodes and {}s only as a whole: all or nothing (seed "
          "§4.2.2), not for node '{}' alone",
          tx, it->second.what, changes.size(), commit ? "commit" : "abort", node));
    }
  }
  const bool whole = node.empty() || (changes.size() == 1 && changes.begin()->first == node);
  if (commit && whole) {
    // Before the changes below end the memberships of the jobs they remove.
    for (const auto& j : it->second.displaced_members) lost_.emplace(j.id, j);
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
      for (const auto& s : ch.sections) n.committed = n.committed.spliced(n.working, s.lo, s.hi);
      for (const auto& r : ch.removed) {
        std::erase_if(n.committed_jobs, [&](const Job& j) { return j.id == r.id; });
      }
      for (const auto& id : ch.added) {
        for (const auto& j : n.working_jobs) {
          if (j.id == id) n.committed_jobs.push_back(j);
        }
        lost_.erase(id);  // a lost set member placed again
      }
      std::sort(n.committed_jobs.begin(), n.committed_jobs.end(), by_start);
    } else {
      for (const auto& s : ch.sections) n.working = n.working.spliced(n.committed, s.lo, s.hi);
      for (const auto& id : ch.added) {
        std::erase_if(n.working_jobs, [&](const Job& j) { return j.id == id; });
      }
      for (const auto& r : ch.removed) n.working_jobs.push_back(r);
      std::sort(n.working_jobs.begin(), n.working_jobs.end(), by_start);
    }
    std::erase_if(n.locks, [&](const NodeState::Lock& l) { return l.tx == tx; });
    // A job's set membership ends with the job (a lost member's when its set gives it up).
    for (const auto& id : ch.added) {
      if (!job_exists(id) && !lost_.contains(id)) sets_.erase(id);
    }
    for (const auto& r : ch.removed) {
      if (!job_exists(r.id) && !lost_.contains(r.id)) sets_.erase(r.id);
    }
    c = changes.erase(c);
  }
  if (changes.empty() || node.empty()) {
    if (commit) {
      for (const auto& id : it->second.lost_given_up) {
        lost_.erase(id);
        sets_.erase(id);
      }
    }
    transactions_.erase(it);
  }
}

void Scheduler::remove_node(const std::string& id) {
  const auto it =
      std::find_if(nodes_.begin(), nodes_.end(), [&](const auto& n) { return n->spec.id == id; });
  if (it == nodes_.end()) throw std::invalid_argument(fmt::format("unknown node id '{}'", id));
  const NodeState& n = **it;
  if (!n.locks.empty()) {
    throw std::invalid_argument(fmt::format(
        "node '{}' cannot be removed: open transaction {} changes it (commit or abort it first)",
        id, n.locks.front().tx));
  }
  for (const auto& j : n.working_jobs) {
    if (j.end() > settings_.present) {
      throw std::invalid_argument(fmt::format(
          "node '{}' cannot be removed: job '{}' ends at {}, after the present {} (seed §5.5.2: "
          "only a node without unfinished jobs; unschedule them first)",
          id, j.id, j.end(), settings_.present));
    }
  }
  for (const auto& j : n.working_jobs) sets_.erase(j.id);
  nodes_.erase(it);
}

std::vector<Job> Scheduler::break_down(const std::string& id, double t, const Point& where) {
  NodeState& n = state(id);
  if (n.broken) throw std::invalid_argument(fmt::format("node '{}' broke down already", id));
  check_time(t, fmt::format("node '{}' breakdown time", id));
  if (t < settings_.present) {
    throw std::invalid_argument(fmt::format("node '{}': breakdown time {} is before the present {}",
                                            id, t, settings_.present));
  }
  if (!n.locks.empty()) {
    throw std::invalid_argument(fmt::format(
        "node '{}': open transaction {} changes it (abort it first)", id, n.locks.front().tx));
  }
  std::vector<Job> lost;
  for (const auto& j : n.committed_jobs) {
    if (j.end() > t) lost.push_back(j);
  }
  for (const auto& j : lost) {
    std::erase_if(n.committed_jobs, [&](const Job& k) { return k.id == j.id; });
    if (set_of(j.id)) lost_.emplace(j.id, j);  // stays in its set until placed again or given up
  }
  const Trajectory standing({{where.x(), where.y(), t}});
  n.committed = n.committed.spliced(standing, t, kForever);
  n.working = n.committed;
  n.working_jobs = n.committed_jobs;
  n.broken = true;
  return lost;
}

bool Scheduler::broken_down(const std::string& id) const { return state(id).broken; }

void Scheduler::forget_before(double t) {
  if (t > settings_.present) {
    throw std::invalid_argument(
        fmt::format("forget_before: {} lies after the present {}", t, settings_.present));
  }
  auto from_t = [t](const Trajectory& tr) {
    if (tr.empty() || tr.start_time() >= t) return tr;
    Trajectory rest;
    const Point p = tr.position_at(t);
    rest.append({p.x(), p.y(), t});
    for (const auto& w : tr.points()) {
      if (w.t > t) rest.append(w);
    }
    return rest;
  };
  auto ended = [t](const Job& j) { return j.end() < t; };
  for (auto& n : nodes_) {
    n->committed = from_t(n->committed);
    n->working = from_t(n->working);
    for (const auto& j : n->committed_jobs) {
      if (ended(j)) sets_.erase(j.id);
    }
    std::erase_if(n->committed_jobs, ended);
    std::erase_if(n->working_jobs, ended);
    n->spec.t = std::max(n->spec.t, t);  // the first pause starts here now
  }
}

std::vector<Scheduler::NodeChange> Scheduler::changes(TransactionId id) const {
  const auto it = transactions_.find(id);
  if (it == transactions_.end()) {
    throw std::invalid_argument(fmt::format("unknown or finished transaction {}", id));
  }
  std::vector<NodeChange> result;
  for (const auto& [node, ch] : it->second.changes) {
    NodeChange c{node, {}, {}, {}};
    for (const auto& s : ch.sections) c.sections.emplace_back(s.lo, s.hi);
    const auto& working = state(node).working_jobs;
    for (const auto& added : ch.added) {
      for (const auto& j : working) {
        if (j.id == added) c.added.push_back(j);
      }
    }
    for (const auto& r : ch.removed) c.removed.push_back(r.id);
    result.push_back(std::move(c));
  }
  return result;
}

void Scheduler::commit(TransactionId id, const std::string& node) { finish(id, node, true); }
void Scheduler::abort(TransactionId id, const std::string& node) { finish(id, node, false); }

}  // namespace oscar::swarm
