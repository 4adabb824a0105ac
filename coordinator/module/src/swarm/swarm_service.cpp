// SwarmService and the heart of its Impl (swarm_service_impl.hpp): the service's thread and its
// status, and requests planned in transactions the robots are asked for.
#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "oscar/time.hpp"
#include "oscar/topics.hpp"
#include "swarm_service_impl.hpp"

namespace oscar::coordinator {

using namespace std::chrono_literals;

SwarmService::Impl::Impl(SwarmSetup s, DdsParticipant& p)
    : setup(std::move(s)),
      participant(p),
      clock{wall_now() / 1'000'000'000 * 1'000'000'000},
      world(live_world(setup.world)),
      scheduler(planned(world, clock, clock.seconds(wall_now())),
                with_present(setup.settings, clock.seconds(wall_now()))),
      client(p, "coordinator") {}

swarm::SchedulerSettings SwarmService::Impl::with_present(swarm::SchedulerSettings s, double now) {
  s.present = now;
  return s;
}

void SwarmService::Impl::post(Event e) {
  {
    std::lock_guard lock(mutex);
    events.push_back(std::move(e));
  }
  wake.notify_all();
}

RobotLink& SwarmService::Impl::link_to(const std::string& module) {
  auto& link = links[module];
  if (!link) {
    link = std::make_unique<RobotLink>(client, module, setup.ack_timeout,
                                       [this](RobotLink::Answer a) { post(std::move(a)); });
  }
  return *link;
}

void SwarmService::Impl::start() {
  for (const auto& r : setup.robots) {
    RobotLink* link = &link_to(r.module);
    Robot robot;
    robot.setup = r;
    robot.link = link;
    robot.state = std::make_unique<CueFeed<RobotState>>(participant, r.kernel + "/state");
    robots.emplace(r.kernel, std::move(robot));
  }
  replies = std::make_unique<TopicWriter<SwarmReply, SwarmReplyPubSubType>>(participant,
                                                                            topics::swarm_reply());
  status_writer = std::make_unique<TopicWriter<SwarmStatus, SwarmStatusPubSubType>>(
      participant, topics::swarm_status());
  plan_writer = std::make_unique<TopicWriter<SwarmPlan, SwarmPlanPubSubType>>(participant,
                                                                              topics::swarm_plan());
  tell_monitors();
  thread = std::thread([this] { run(); });
  requests = std::make_unique<TopicReader<SwarmRequest, SwarmRequestPubSubType>>(
      participant, topics::swarm_request(),
      [this](const SwarmRequest& r, const auto&) { post(r); });
}

void SwarmService::Impl::stop() {
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

void SwarmService::Impl::run() {
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

void SwarmService::Impl::reply(const Request& r, SwarmOutcome outcome, TransactionId tx,
                               std::string reason, const std::vector<swarm::Job>& jobs) {
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

void SwarmService::Impl::handle(const SwarmRequest& message) {
  auto r = std::make_shared<Request>();
  r->message = message;
  counters.jobs_submitted(counters.jobs_submitted() + jobs_in(message));
  if (!held.empty()) {
    held.push_back(r);
    return;
  }
  plan(r);
}

void SwarmService::Impl::release_held() {
  while (!held.empty() && (pending.empty() || !changes_world(held.front()->message))) {
    auto r = held.front();
    held.pop_front();
    plan(r);
  }
}

bool SwarmService::Impl::changes_world(const SwarmRequest& m) {
  return m.kind() == SWARM_ADD_OBSTACLES || m.kind() == SWARM_REMOVE_OBSTACLES;
}

std::uint64_t SwarmService::Impl::jobs_in(const SwarmRequest& m) {
  if (m.kind() == SWARM_PERIODIC) return m.periodic_ids().size();
  if (m.kind() == SWARM_DEPENDENT) return m.jobs().size();
  return m.kind() == SWARM_SCHEDULE || m.kind() == SWARM_RESCHEDULE ? 1 : 0;
}

void SwarmService::Impl::plan(const std::shared_ptr<Request>& r) {
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
                             : fmt::format("planned {} times, robots refused: {}", r->attempts + 1,
                                           result.reason));
    return;
  }
  propose(r, result.transaction, result.jobs, {});
}

void SwarmService::Impl::propose(const std::shared_ptr<Request>& r, TransactionId tx,
                                 std::vector<swarm::Job> jobs, std::vector<swarm::Job> displaced) {
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

void SwarmService::Impl::handle(const RobotLink::Answer& a) {
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

void SwarmService::Impl::finish(TransactionId tx, const Pending& p) {
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

void SwarmService::Impl::give_up(const Request& r, SwarmOutcome outcome, TransactionId tx,
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

void SwarmService::Impl::end_set(const Request& r, const std::string& why) {
  auto end = std::make_shared<Request>();
  end->message = r.message;
  end->message.kind(SWARM_UNSCHEDULE_SET);
  end->message.job_id(r.lost->member);
  end->ends_set_because = fmt::format("{} and the {} cannot be whole again: {}", r.lost->cause,
                                      scheduler.set_name(r.lost->member), why);
  spdlog::warn("swarm: {}", end->ends_set_because);
  plan(end);
}

void SwarmService::Impl::publish_status(std::int64_t now) {
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
