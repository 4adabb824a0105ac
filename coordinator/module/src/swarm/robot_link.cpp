#include "robot_link.hpp"

#include <stdexcept>

#include <spdlog/spdlog.h>

#include "oscar/swarm_types.hpp"

namespace oscar::coordinator {

RobotLink::RobotLink(ConfigClient& client, std::string module, std::chrono::milliseconds timeout,
                     OnAnswer on_answer)
    : client_(client),
      module_(std::move(module)),
      timeout_(timeout),
      on_answer_(std::move(on_answer)),
      thread_([this] { run(); }) {
  client_.connect(module_);  // discovered by the first proposal, which has only the ACK timeout
}

RobotLink::~RobotLink() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void RobotLink::post(Message m) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(m));
  }
  wake_.notify_all();
}

void RobotLink::propose(Trajectory trajectory) { post(std::move(trajectory)); }

void RobotLink::commit(const std::string& robot, unsigned long long transaction) {
  TransactionDecision d;
  d.robot(robot);
  d.transaction(transaction);
  post(Decision{"commit", d});
}

void RobotLink::abort(const std::string& robot, unsigned long long transaction) {
  TransactionDecision d;
  d.robot(robot);
  d.transaction(transaction);
  post(Decision{"abort", d});
}

void RobotLink::tell_world(const std::string& monitor, SwarmWorld world) {
  post(WorldNews{monitor, std::move(world)});
}

std::string RobotLink::committed(const std::string& robot) {
  CommittedPlanQuery q;
  q.robot(robot);
  const auto reply = client_.command(module_, robot, "committed", q, timeout_);
  if (!reply.ok()) throw std::invalid_argument(reply.error());
  return reply.answer();
}

void RobotLink::run() {
  for (;;) {
    Message m;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;  // what is left is moot: the coordinator stops
      m = std::move(queue_.front());
      queue_.pop_front();
    }
    std::visit([this](const auto& x) { send(x); }, m);
  }
}

void RobotLink::send(const Trajectory& t) {
  Answer a{t.robot(), t.transaction(), false, false, {}};
  try {
    const auto reply = client_.command(module_, t.robot(), "propose", t, timeout_);
    a.ack = reply.ok();
    a.reason = reply.ok() ? reply.answer() : reply.error();
  } catch (const std::runtime_error& e) {
    a.silent = true;
    a.reason = e.what();
  }
  on_answer_(std::move(a));
}

void RobotLink::send(const Decision& d) {
  // A decision is told, not negotiated: a robot that missed it is out of step, which its next
  // proposal's check (it starts where the robot will be) shows.
  try {
    const auto reply = client_.command(module_, d.decision.robot(), d.name, d.decision, timeout_);
    if (!reply.ok()) {
      spdlog::warn("swarm: robot '{}' refused {} of transaction {}: {}", d.decision.robot(), d.name,
                   d.decision.transaction(), reply.error());
    }
  } catch (const std::runtime_error& e) {
    spdlog::warn("swarm: robot '{}' did not take {} of transaction {}: {}", d.decision.robot(),
                 d.name, d.decision.transaction(), e.what());
  }
}

void RobotLink::send(const WorldNews& w) {
  try {
    const auto reply = client_.command(module_, w.monitor, "world", w.world, timeout_);
    if (!reply.ok()) {
      spdlog::error("swarm: safety monitor '{}' refused the world: {}", w.monitor, reply.error());
    }
  } catch (const std::exception& e) {
    spdlog::warn("swarm: safety monitor '{}' was not told the world: {}", w.monitor, e.what());
  }
}

}  // namespace oscar::coordinator
