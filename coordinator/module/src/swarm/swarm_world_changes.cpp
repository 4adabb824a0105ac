// The live swarm's world (SwarmService::Impl, swarm_service_impl.hpp; docs/swarm.md, "A world
// that changes"): as the planner and the safety monitors get it, and its changes at run time.
#include <stdexcept>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "swarm_service_impl.hpp"

namespace oscar::coordinator {

LiveWorld SwarmService::Impl::live_world(const std::vector<SwarmObstacle>& obstacles) {
  LiveWorld w;
  for (const auto& o : obstacles) w.add(o);
  return w;
}

swarm::World SwarmService::Impl::planned(const LiveWorld& w, const swarm_wire::Clock& clock,
                                         double now) {
  return w.planned(clock, now - 1, now + LiveWorld::kLoopSpan);
}

void SwarmService::Impl::tell_monitors() {
  for (const auto& m : setup.monitors) link_to(m.module).tell_world(m.kernel, world.wire());
}

void SwarmService::Impl::plan_world(const std::shared_ptr<Request>& r) {
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

void SwarmService::Impl::renew_world() {
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

}  // namespace oscar::coordinator
