#include "oscar/coordinator/swarm_service.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "live_world.hpp"
#include "oscar/config_client.hpp"
#include "oscar/coordinator/cue_feed.hpp"
#include "oscar/swarm_types.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"
#include "robot_link.hpp"
#include "swarm_wire.hpp"

namespace oscar::coordinator {

using swarm::TransactionId;
using namespace std::chrono_literals;

struct SwarmService::Impl {
  // A request, how often it was planned and the robots that refused it (not asked again).
  struct Request {
    SwarmRequest message;
    int attempts = 0;
    std::set<std::string> refused_by;
    // Set by lose(): instead of the message, the request places again the members of a job set
    // that a broken-down robot lost (any one of them names the set).
    struct LostMembers {
      std::string member;
      std::string cause;  // "robot 'r3' broke down", "the world changed"
    };
    std::optional<LostMembers> lost;
    // Set by end_set(): the message unschedules a set that cannot be whole again, and its
    // requester hears ABORTED for this reason.
    std::string ends_set_because;
    // A world change (add or remove obstacles): the world it makes, while it is planned.
    std::optional<LiveWorld> next_world;
  };
  // A transaction waiting for its robots' answers.
  struct Pending {
    std::shared_ptr<Request> request;
    std::set<std::string> asked, waiting;
    std::vector<swarm::Job> jobs;
    std::vector<swarm::Job> displaced;  // a world change's: placed again once it commits
  };
  struct Robot {
    SwarmSetup::Robot setup;
    std::unique_ptr<CueFeed<RobotState>> state;
    RobotLink* link = nullptr;
    bool planned = false;  // added to the scheduler
    bool lost = false;     // broke down or fell silent: out of planning
    std::int64_t last_heard_ns = 0;
    std::uint64_t states_seen = 0;
    std::int64_t ask_again_ns = 0;  // it did not tell its committed plan: not before then
  };
  using Event = std::variant<SwarmRequest, RobotLink::Answer>;

  SwarmSetup setup;
  DdsParticipant& participant;
  swarm_wire::Clock clock;
  LiveWorld world;
  swarm::Scheduler scheduler;
  ConfigClient client;
  std::map<std::string, std::unique_ptr<RobotLink>> links;  // by module
  std::map<std::string, Robot> robots;
  std::map<TransactionId, Pending> pending;
  // Requests held while a world change waits for the open transactions to finish (it must not
  // meet half-applied plans), in the order they came.
  std::deque<std::shared_ptr<Request>> held;
  // Where each committed job came from, to place it again when its robot breaks down.
  std::map<std::string, std::shared_ptr<Request>> origin;
  SwarmStatus counters;

  std::mutex mutex;
  std::condition_variable wake;
  std::deque<Event> events;
  bool stopping = false;
  SwarmStatus published;
  std::thread thread;
  std::unique_ptr<TopicWriter<SwarmReply, SwarmReplyPubSubType>> replies;
  std::unique_ptr<TopicWriter<SwarmStatus, SwarmStatusPubSubType>> status_writer;
  std::unique_ptr<TopicWriter<SwarmPlan, SwarmPlanPubSubType>> plan_writer;
  bool plan_changed = true;  // the committed plan changed since it was last published
  std::unique_ptr<TopicReader<SwarmRequest, SwarmRequestPubSubType>> requests;

  Impl(SwarmSetup s, DdsParticipant& p)
      : setup(std::move(s)),
        participant(p),
        clock{wall_now() / 1'000'000'000 * 1'000'000'000},
        world(live_world(setup.world)),
        scheduler(planned(world, clock, clock.seconds(wall_now())),
                  with_present(setup.settings, clock.seconds(wall_now()))),
        client(p, "coordinator") {}

  static LiveWorld live_world(const std::vector<SwarmObstacle>& obstacles) {
    LiveWorld w;
    for (const auto& o : obstacles) w.add(o);
    return w;
  }

  // The planner's world from just before `now` until loops must be unrolled again.
  static swarm::World planned(const LiveWorld& w, const swarm_wire::Clock& clock, double now) {
    return w.planned(clock, now - 1, now + LiveWorld::kLoopSpan);
  }

  static swarm::SchedulerSettings with_present(swarm::SchedulerSettings s, double now) {
    s.present = now;
    return s;
  }

  void post(Event e) {
    {
      std::lock_guard lock(mutex);
      events.push_back(std::move(e));
    }
    wake.notify_all();
  }

  RobotLink& link_to(const std::string& module) {
    auto& link = links[module];
    if (!link) {
      link = std::make_unique<RobotLink>(client, module, setup.ack_timeout,
                                         [this](RobotLink::Answer a) { post(std::move(a)); });
    }
    return *link;
  }

  void tell_monitors() {
    for (const auto& m : setup.monitors) link_to(m.module).tell_world(m.kernel, world.wire());
  }

  void start() {
    for (const auto& r : setup.robots) {
      RobotLink* link = &link_to(r.module);
      Robot robot;
      robot.setup = r;
      robot.link = link;
      robot.state = std::make_unique<CueFeed<RobotState>>(participant, r.kernel + "/state");
      robots.emplace(r.kernel, std::move(robot));
    }
    replies = std::make_unique<TopicWriter<SwarmReply, SwarmReplyPubSubType>>(
        participant, topics::swarm_reply());
    status_writer = std::make_unique<TopicWriter<SwarmStatus, SwarmStatusPubSubType>>(
        participant, topics::swarm_status());
    plan_writer = std::make_unique<TopicWriter<SwarmPlan, SwarmPlanPubSubType>>(
        participant, topics::swarm_plan());
    tell_monitors();
    thread = std::thread([this] { run(); });
    requests = std::make_unique<TopicReader<SwarmRequest, SwarmRequestPubSubType>>(
        participant, topics::swarm_request(),
        [this](const SwarmRequest& r, const auto&) { post(r); });
  }

  void stop() {
    requests.reset();
    {
      std::lock_guard lock(mutex);
      if (stopping) return;
      stopping = true;
    }
    wake.notify_all();
    if (thread.joinable()) thread.join();
    links.clear();  // before the feeds and the client they use
    robots.clear();
  }

  void run() {
    auto next_status = std::chrono::steady_clock::now();
    auto next_forget = next_status + 10s;
    auto next_world = next_status + kWorldAgain;
    auto next_plan = next_status;
    for (;;) {
      std::deque<Event> batch;
      {
        std::unique_lock lock(mutex);
        wake.wait_for(lock, 50ms, [&] { return stopping || !events.empty(); });
        if (stopping) return;
        batch.swap(events);
      }
      const auto now = wall_now();
      scheduler.set_present(std::max(scheduler.present(), clock.seconds(now)));
      watch_robots(now);
      for (auto& e : batch) {
        try {
          std::visit([this](auto& x) { handle(x); }, e);
          release_held();
        } catch (const std::exception& ex) {
          spdlog::error("swarm: {}", ex.what());  // a bug of ours: said, and the loop goes on
        }
      }
      if (std::chrono::steady_clock::now() >= next_world) {
        renew_world();
        next_world = std::chrono::steady_clock::now() + kWorldAgain;
      }
      if (!batch.empty() || std::chrono::steady_clock::now() >= next_status) {
        publish_status(now);
        next_status = std::chrono::steady_clock::now() + 1s;
      }
      if (plan_changed && std::chrono::steady_clock::now() >= next_plan) {
        plan_writer->write(swarm_wire::plan(scheduler, clock));
        plan_changed = false;
        next_plan = std::chrono::steady_clock::now() + 500ms;  // at most twice a second
      }
      if (std::chrono::steady_clock::now() >= next_forget) {
        forget_history();
        next_forget = std::chrono::steady_clock::now() + 10s;
      }
    }
  }

  // ---- requests ----

  void reply(const Request& r, SwarmOutcome outcome, TransactionId tx, std::string reason,
             const std::vector<swarm::Job>& jobs = {}) {
    if (!r.ends_set_because.empty()) {  // the set's requester hears of its end, not of the means
      if (outcome == SWARM_PLANNED) return;
      reason = outcome == SWARM_COMMITTED
                   ? r.ends_set_because + "; its members not started are unscheduled"
                   : fmt::format("{}; its members not started could not be unscheduled: {}",
                                 r.ends_set_because, reason);
      outcome = SWARM_ABORTED;
    }
    if (r.message.sender().empty()) return;  // the service's own request (renew_world)
    SwarmReply m;
    m.sender(r.message.sender());
    m.request(r.message.id());
    m.outcome(outcome);
    m.transaction(tx);
    m.reason(reason);
    for (const auto& j : jobs) m.jobs().push_back(swarm_wire::placed(j, clock));
    replies->write(m);
  }

  void handle(const SwarmRequest& message) {
    auto r = std::make_shared<Request>();
    r->message = message;
    counters.jobs_submitted(counters.jobs_submitted() + jobs_in(message));
    if (!held.empty()) {
      held.push_back(r);
      return;
    }
    plan(r);
  }

  // Plans the held requests in order, until a world change meets open transactions.
  void release_held() {
    while (!held.empty() && (pending.empty() || !changes_world(held.front()->message))) {
      auto r = held.front();
      held.pop_front();
      plan(r);
    }
  }

  static bool changes_world(const SwarmRequest& m) {
    return m.kind() == SWARM_ADD_OBSTACLES || m.kind() == SWARM_REMOVE_OBSTACLES;
  }

  static std::uint64_t jobs_in(const SwarmRequest& m) {
    if (m.kind() == SWARM_PERIODIC) return m.periodic_ids().size();
    if (m.kind() == SWARM_DEPENDENT) return m.jobs().size();
    return m.kind() == SWARM_SCHEDULE || m.kind() == SWARM_RESCHEDULE ? 1 : 0;
  }

  void plan(const std::shared_ptr<Request>& r) {
    if (changes_world(r->message)) {
      plan_world(r);
      return;
    }
    swarm::ScheduleResult result;
    scheduler.set_excluded(r->refused_by);
    try {
      result = r->lost ? scheduler.schedule_lost(r->lost->member)
                       : swarm_wire::apply(scheduler, r->message, clock);
    } catch (const std::invalid_argument& e) {
      scheduler.set_excluded({});
      reply(*r, SWARM_REFUSED, 0, e.what());
      return;
    }
    scheduler.set_excluded({});
    if (!result.ok) {
      give_up(*r, r->attempts == 0 ? SWARM_REFUSED : SWARM_ABORTED, 0,
              r->attempts == 0 ? result.reason
                               : fmt::format("planned {} times, robots refused: {}",
                                             r->attempts + 1, result.reason));
      return;
    }
    propose(r, result.transaction, result.jobs, {});
  }

  // Asks the robots a transaction changes; it commits when they all acknowledged.
  void propose(const std::shared_ptr<Request>& r, TransactionId tx, std::vector<swarm::Job> jobs,
               std::vector<swarm::Job> displaced) {
    Pending p{r, {}, {}, std::move(jobs), std::move(displaced)};
    if (tx == 0) {  // nothing to ask anyone (a world change nobody runs into)
      finish(tx, p);
      return;
    }
    for (const auto& change : scheduler.changes(tx)) {
      auto it = robots.find(change.node);
      p.asked.insert(change.node);
      it->second.link->propose(swarm_wire::proposal(scheduler, tx, change, clock));
    }
    p.waiting = p.asked;
    reply(*r, SWARM_PLANNED, tx, "", p.jobs);
    if (p.asked.empty()) {
      finish(tx, p);
      return;
    }
    pending.emplace(tx, std::move(p));
  }

  void handle(const RobotLink::Answer& a) {
    auto it = pending.find(a.transaction);
    if (it == pending.end()) return;  // the transaction aborted already
    Pending& p = it->second;
    if (a.ack) {
      p.waiting.erase(a.robot);
      if (p.waiting.empty()) {
        Pending done = std::move(p);
        pending.erase(it);
        finish(a.transaction, done);
      }
      return;
    }
    if (a.silent) {
      counters.timeouts(counters.timeouts() + 1);
    } else {
      counters.naks(counters.naks() + 1);
    }
    spdlog::info("swarm: robot '{}' {} transaction {}: {}", a.robot,
                 a.silent ? "did not answer" : "refused", a.transaction, a.reason);
    Pending failed = std::move(p);
    pending.erase(it);
    scheduler.abort(a.transaction);
    for (const auto& robot : failed.asked) {
      // A silent robot may still have taken the proposal: it hears the abort as well.
      if (robot != a.robot || a.silent) robots.at(robot).link->abort(robot, a.transaction);
    }
    auto& r = failed.request;
    r->refused_by.insert(a.robot);
    if (r->attempts >= setup.replan_attempts) {
      give_up(*r, SWARM_ABORTED, a.transaction,
              fmt::format("robot '{}' {}: {} (planned {} times)", a.robot,
                          a.silent ? "did not answer" : "refused", a.reason, r->attempts + 1));
      return;
    }
    ++r->attempts;
    counters.replans(counters.replans() + 1);
    plan(r);
  }

  void finish(TransactionId tx, const Pending& p) {
    if (tx) scheduler.commit(tx);
    plan_changed = true;
    for (const auto& robot : p.asked) robots.at(robot).link->commit(robot, tx);
    for (const auto& j : p.jobs) origin[j.id] = p.request;
    counters.jobs_committed(counters.jobs_committed() + p.jobs.size());
    if (p.request->next_world) {
      world = std::move(*p.request->next_world);
      p.request->next_world.reset();
      tell_monitors();
    }
    reply(*p.request, SWARM_COMMITTED, tx, "", p.jobs);
    for (auto& again : requests_to_place(p.displaced, "the world changed", {})) {
      counters.replans(counters.replans() + 1);
      plan(again);
    }
  }

  // ---- the world ----

  // How often loops are unrolled again and the monitors told the world again (a monitor that
  // restarted has only its parameters).
  static constexpr auto kWorldAgain = 30s;

  // A world change is planned when no transaction is open: nodes that run into the new world
  // after the frozen horizon are planned again in one transaction (Scheduler::change_world), and
  // the world is the new one once it commits. Obstacles added count from the frozen horizon on.
  void plan_world(const std::shared_ptr<Request>& r) {
    if (!pending.empty()) {
      held.push_front(r);
      return;
    }
    LiveWorld next = world;
    try {
      if (r->message.kind() == SWARM_ADD_OBSTACLES) {
        if (r->message.obstacles().empty() && !r->message.sender().empty()) {
          throw std::invalid_argument("add_obstacles: no obstacle given");
        }
        for (auto o : r->message.obstacles()) {
          o.since_ns(clock.ns(scheduler.frozen_horizon_time()));
          next.add(std::move(o));
        }
      } else {
        if (r->message.obstacle_names().empty()) {
          throw std::invalid_argument("remove_obstacles: no obstacle named");
        }
        for (const auto& name : r->message.obstacle_names()) next.remove(name);
      }
      const auto change = scheduler.change_world(planned(next, clock, scheduler.present()));
      if (!change.ok) {
        give_up(*r, r->attempts == 0 ? SWARM_REFUSED : SWARM_ABORTED, 0, change.reason);
        return;
      }
      r->next_world = std::move(next);
      if (!change.nodes.empty()) {
        spdlog::info("swarm: the world changes ({}); robots planned again: {}",
                     swarm_wire::kind_name(r->message.kind()), fmt::join(change.nodes, ", "));
      }
      propose(r, change.transaction, {}, change.displaced);
    } catch (const std::invalid_argument& e) {
      reply(*r, SWARM_REFUSED, 0, e.what());
    }
  }

  // Loops are unrolled for a span ahead: before the present gets near its end they are
  // unrolled again (a world change that changes nothing else), and the monitors hear the world.
  void renew_world() {
    tell_monitors();
    if (!world.has_loops()) return;
    auto r = std::make_shared<Request>();
    r->message.kind(SWARM_ADD_OBSTACLES);  // nothing: the same world, unrolled from now
    if (held.empty() && pending.empty()) {
      plan(r);
    } else {
      held.push_back(r);
    }
  }

  // ---- robots ----

  void watch_robots(std::int64_t now) {
    for (auto& [id, robot] : robots) {
      if (robot.lost) continue;
      const auto state = robot.state->latest();
      if (robot.state->received() != robot.states_seen) {
        robot.states_seen = robot.state->received();
        robot.last_heard_ns = now;
      }
      if (!state) continue;
      if (!robot.planned && !state->broken()) {
        if (now >= robot.ask_again_ns) add(robot, *state, now);
      } else if (robot.planned && state->broken()) {
        lose(robot, *state, "broke down: " + state->fault());
      } else if (robot.planned &&
                 now - robot.last_heard_ns > std::chrono::nanoseconds(setup.lost_after).count()) {
        lose(robot, *state,
             fmt::format("sent no state for {} ms", (now - robot.last_heard_ns) / 1'000'000));
      }
    }
  }

  // A robot joins planning with what it has committed: idle where it stands, or (after this
  // coordinator restarted) driving the trajectory and working the jobs its predecessor
  // committed, which the planner takes over as they are.
  void add(Robot& robot, const RobotState& s, std::int64_t now) {
    const std::string& id = robot.setup.kernel;
    std::string answer;
    try {
      answer = robot.link->committed(id);
    } catch (const std::invalid_argument& e) {
      robot.lost = true;
      spdlog::error("swarm: robot '{}' cannot be planned: it does not tell its committed plan: {}",
                    id, e.what());
      return;
    } catch (const std::runtime_error& e) {
      robot.ask_again_ns = now + std::chrono::nanoseconds(1s).count();
      spdlog::warn("swarm: robot '{}' did not tell its committed plan ({}); asked again in 1 s", id,
                   e.what());
      return;
    }
    try {
      // It drove on while it answered: its plan holds from its time of answering.
      const auto plan = take_over(id, answer);
      const swarm::Point here = plan.trajectory.position_at(scheduler.present());
      swarm::NodeSpec spec{id,       s.radius(),          s.max_speed(),     here.x(),
                           here.y(), scheduler.present(), s.turning_radius()};
      if (plan.idle()) {
        scheduler.add_node(spec);
        spdlog::info("swarm: robot '{}' joins planning at ({:.2f}, {:.2f})", id, spec.x, spec.y);
      } else {
        scheduler.add_node(spec, plan.trajectory, plan.jobs);
        for (const auto& j : plan.jobs) origin[j.id] = taken_over_request(j);
        spdlog::info(
            "swarm: robot '{}' joins planning at ({:.2f}, {:.2f}) with its committed plan: a "
            "trajectory until {:.1f} s from now and {} job(s){}",
            id, spec.x, spec.y, std::max(0.0, plan.trajectory.end_time() - spec.t),
            plan.jobs.size(), plan.jobs.empty() ? "" : ": " + job_ids(plan.jobs));
      }
      robot.planned = true;
      plan_changed = true;
    } catch (const std::invalid_argument& e) {
      robot.lost = true;
      spdlog::error("swarm: robot '{}' cannot be planned: {}", id, e.what());
    }
  }

  // A robot's answer to `committed` in the planner's terms; the present moves on to the
  // robot's time of answering if that is later.
  swarm_wire::CommittedPlan take_over(const std::string& id, const std::string& answer) {
    auto plan = swarm_wire::committed_plan(id, answer, clock);
    const double t =
        std::max({scheduler.present(), clock.seconds(wall_now()), plan.trajectory.start_time()});
    scheduler.set_present(t);
    std::erase_if(plan.jobs, [&](const swarm::Job& j) { return j.end() < t; });  // done
    return plan;
  }

  // Where a job taken over from a robot's committed plan came from, to place it again when the
  // robot breaks down: its requester is not known, so the coordinator stands in for it.
  std::shared_ptr<Request> taken_over_request(const swarm::Job& j) const {
    auto r = std::make_shared<Request>();
    r->message.sender("coordinator");
    r->message.kind(SWARM_SCHEDULE);
    r->message.jobs().push_back(swarm_wire::wire_job_spec(j.spec, clock));
    return r;
  }

  static std::string job_ids(const std::vector<swarm::Job>& jobs) {
    std::string ids;
    for (const auto& j : jobs) ids += (ids.empty() ? "" : ", ") + j.id;
    return ids;
  }

  void lose(Robot& robot, const RobotState& s, const std::string& why) {
    const std::string id = robot.setup.kernel;
    robot.lost = true;
    spdlog::warn("swarm: robot '{}' {}; it leaves planning and its jobs go to others", id, why);
    // Its open transactions abort first (the planner needs the robot unlocked), and go again.
    std::vector<std::shared_ptr<Request>> again;
    for (auto it = pending.begin(); it != pending.end();) {
      if (!it->second.asked.count(id)) {
        ++it;
        continue;
      }
      scheduler.abort(it->first);
      for (const auto& r : it->second.asked) robots.at(r).link->abort(r, it->first);
      again.push_back(it->second.request);
      it = pending.erase(it);
    }
    const auto jobs = scheduler.break_down(id, scheduler.present(), swarm::Point(s.x(), s.y()));
    plan_changed = true;
    for (auto& r : requests_to_place(jobs, fmt::format("robot '{}' broke down", id), again)) {
      counters.replans(counters.replans() + 1);
      plan(r);
    }
  }

  // The requests that place `jobs` again (removed from a robot that broke down, or displaced by
  // a changed world), after those in `again`: a single job alone, in its original window; the
  // lost members of a set together, within the set, once per set.
  std::vector<std::shared_ptr<Request>> requests_to_place(
      const std::vector<swarm::Job>& jobs, const std::string& cause,
      std::vector<std::shared_ptr<Request>> again) {
    for (const auto& j : jobs) {
      auto from = origin.find(j.id);
      if (from == origin.end()) continue;
      if (const std::string set = scheduler.set_name(j.id); !set.empty()) {
        if (!handles_set(again, set)) {
          auto r = std::make_shared<Request>(*from->second);
          r->attempts = 0;
          r->lost = Request::LostMembers{j.id, cause};
          again.push_back(r);
        }
        origin.erase(from);
        continue;
      }
      auto r = std::make_shared<Request>(*from->second);
      r->message.kind(SWARM_SCHEDULE);
      r->message.jobs().clear();
      auto spec = swarm_wire::wire_job_spec(j.spec, clock);
      spec.id(j.id);
      r->message.jobs().push_back(spec);
      r->attempts = 0;
      origin.erase(from);
      again.push_back(r);
    }
    return again;
  }

  // True if one of `planned` places the lost members of `set` again or ends the set.
  bool handles_set(const std::vector<std::shared_ptr<Request>>& planned,
                   const std::string& set) const {
    return std::any_of(planned.begin(), planned.end(), [&](const auto& r) {
      const std::string member = r->lost                       ? r->lost->member
                                 : r->ends_set_because.empty() ? std::string()
                                                               : r->message.job_id();
      return !member.empty() && scheduler.set_name(member) == set;
    });
  }

  // A request that cannot be planned (any more): its requester hears why; a set that a
  // broken-down robot left short and that cannot be whole again ends.
  void give_up(const Request& r, SwarmOutcome outcome, TransactionId tx,
               const std::string& reason) {
    if (changes_world(r.message)) {
      if (!r.message.sender().empty()) {
        // The planner goes back to the world as it is, first thing once no transaction is open
        // (a change not made only removes obstacles from the planner's: nobody runs into that).
        auto back = std::make_shared<Request>();
        back->message.kind(SWARM_ADD_OBSTACLES);
        held.push_front(back);
      }
      reply(r, outcome, tx, reason);
    } else if (r.lost) {
      end_set(r, reason);
    } else {
      reply(r, outcome, tx, reason);
    }
  }

  // All or nothing for a set whose lost members cannot be placed again: its members not started
  // are unscheduled (a transaction the robots holding them are asked for, as any), and then its
  // requester hears ABORTED, naming the robot and the set.
  void end_set(const Request& r, const std::string& why) {
    auto end = std::make_shared<Request>();
    end->message = r.message;
    end->message.kind(SWARM_UNSCHEDULE_SET);
    end->message.job_id(r.lost->member);
    end->ends_set_because = fmt::format("{} and the {} cannot be whole again: {}", r.lost->cause,
                                        scheduler.set_name(r.lost->member), why);
    spdlog::warn("swarm: {}", end->ends_set_because);
    plan(end);
  }

  // What ended more than a minute ago is history: the planner and the origins forget it.
  void forget_history() {
    const double before = scheduler.present() - 60;
    if (before <= clock.seconds(clock.epoch_ns)) return;
    scheduler.forget_before(before);
    plan_changed = true;
    std::set<std::string> planned;
    for (const auto& id : scheduler.node_ids()) {
      for (const auto& j : scheduler.jobs(id, false)) planned.insert(j.id);
    }
    std::erase_if(origin, [&](const auto& entry) { return !planned.contains(entry.first); });
  }

  // ---- status ----

  void publish_status(std::int64_t now) {
    SwarmStatus s = counters;
    s.now_ns(now);
    for (const auto& [id, robot] : robots) {
      if (robot.planned && !robot.lost) s.robots().push_back(id);
      if (robot.lost) s.lost_robots().push_back(id);
    }
    s.jobs(swarm_wire::upcoming_jobs(scheduler, clock));
    s.open_transactions(scheduler.open_transactions());
    for (const auto& o : world.obstacles()) s.obstacles().push_back(o.name());
    status_writer->write(s);
    std::lock_guard lock(mutex);
    published = std::move(s);
  }
};

SwarmService::SwarmService(SwarmSetup setup, DdsParticipant& participant)
    : impl_(std::make_unique<Impl>(std::move(setup), participant)) {}

SwarmService::~SwarmService() { stop(); }

void SwarmService::start() { impl_->start(); }
void SwarmService::stop() { impl_->stop(); }

SwarmStatus SwarmService::status() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->published;
}

}  // namespace oscar::coordinator
