// The live swarm's robots (SwarmService::Impl, swarm_service_impl.hpp): joining planning with
// what they committed, and leaving it when they break down or fall silent, their jobs placed
// again on others.
#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "oscar/time.hpp"
#include "swarm_service_impl.hpp"

namespace oscar::coordinator {

using namespace std::chrono_literals;

void SwarmService::Impl::watch_robots(std::int64_t now) {
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

void SwarmService::Impl::add(Robot& robot, const RobotState& s, std::int64_t now) {
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
          id, spec.x, spec.y, std::max(0.0, plan.trajectory.end_time() - spec.t), plan.jobs.size(),
          plan.jobs.empty() ? "" : ": " + job_ids(plan.jobs));
    }
    robot.planned = true;
    plan_changed = true;
  } catch (const std::invalid_argument& e) {
    robot.lost = true;
    spdlog::error("swarm: robot '{}' cannot be planned: {}", id, e.what());
  }
}

swarm_wire::CommittedPlan SwarmService::Impl::take_over(const std::string& id,
                                                        const std::string& answer) {
  auto plan = swarm_wire::committed_plan(id, answer, clock);
  const double t =
      std::max({scheduler.present(), clock.seconds(wall_now()), plan.trajectory.start_time()});
  scheduler.set_present(t);
  std::erase_if(plan.jobs, [&](const swarm::Job& j) { return j.end() < t; });  // done
  return plan;
}

std::shared_ptr<SwarmService::Impl::Request> SwarmService::Impl::taken_over_request(
    const swarm::Job& j) const {
  auto r = std::make_shared<Request>();
  r->message.sender("coordinator");
  r->message.kind(SWARM_SCHEDULE);
  r->message.jobs().push_back(swarm_wire::wire_job_spec(j.spec, clock));
  return r;
}

std::string SwarmService::Impl::job_ids(const std::vector<swarm::Job>& jobs) {
  std::string ids;
  for (const auto& j : jobs) ids += (ids.empty() ? "" : ", ") + j.id;
  return ids;
}

void SwarmService::Impl::lose(Robot& robot, const RobotState& s, const std::string& why) {
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

std::vector<std::shared_ptr<SwarmService::Impl::Request>> SwarmService::Impl::requests_to_place(
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

bool SwarmService::Impl::handles_set(const std::vector<std::shared_ptr<Request>>& planned,
                                     const std::string& set) const {
  return std::any_of(planned.begin(), planned.end(), [&](const auto& r) {
    const std::string member = r->lost                       ? r->lost->member
                               : r->ends_set_because.empty() ? std::string()
                                                             : r->message.job_id();
    return !member.empty() && scheduler.set_name(member) == set;
  });
}

void SwarmService::Impl::forget_history() {
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

}  // namespace oscar::coordinator
