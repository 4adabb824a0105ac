#pragma once
// What the live swarm's integration tests say to the coordinator and hear from it and the robots
// (docs/swarm.md, "The live swarm"): job specifications, requests over DDS, the replies, the
// status, the committed plan and the robots' states.

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "oscar/coordinator/cue_feed.hpp"
#include "oscar/swarm_types.hpp"
#include "oscar/time.hpp"
#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar::test {

// A square job area of side 0.2 m around (x, y), in the window [now + from_s, now + to_s].
inline SwarmJobSpec job(const std::string& id, double x, double y, double from_s, double to_s,
                        double duration_s) {
  SwarmJobSpec j;
  j.id(id);
  j.area().x({x - 0.1, x + 0.1, x + 0.1, x - 0.1});
  j.area().y({y - 0.1, y - 0.1, y + 0.1, y + 0.1});
  const auto now = wall_now();
  j.earliest_start_ns(now + static_cast<Stamp>(from_s * 1e9));
  j.latest_finish_ns(now + static_cast<Stamp>(to_s * 1e9));
  j.duration_s(duration_s);
  return j;
}

// Submits requests and reads the coordinator's replies, status and plan and the robots' states.
class SwarmClient {
 public:
  SwarmClient(DdsParticipant& p, std::string sender)
      : participant_(p),
        sender_(std::move(sender)),
        writer_(p, topics::swarm_request()),
        replies_(p, topics::swarm_reply(),
                 [this](const SwarmReply& r, const auto&) {
                   std::lock_guard lock(mutex_);
                   replies_seen_[r.request()].push_back(r);
                   changed_.notify_all();
                 }),
        status_(p, topics::swarm_status(),
                [this](const SwarmStatus& s, const auto&) {
                  std::lock_guard lock(mutex_);
                  status_seen_ = s;
                  changed_.notify_all();
                }),
        plan_(p, topics::swarm_plan(), [this](const SwarmPlan& s, const auto&) {
          std::lock_guard lock(mutex_);
          plan_seen_ = s;
          changed_.notify_all();
        }) {}

  unsigned long long submit(SwarmRequest r) {
    r.sender(sender_);
    r.id(++next_id_);
    writer_.write(r);
    return r.id();
  }
  unsigned long long schedule(const SwarmJobSpec& j) {
    SwarmRequest r;
    r.kind(SWARM_SCHEDULE);
    r.jobs().push_back(j);
    return submit(r);
  }

  // The first reply to `request` with an outcome other than PLANNED, after `skip` such ones.
  SwarmReply outcome(unsigned long long request, std::size_t skip = 0) {
    using namespace std::chrono_literals;
    std::unique_lock lock(mutex_);
    SwarmReply found;
    const bool ok = changed_.wait_for(lock, 30s, [&] {
      std::size_t n = 0;
      for (const auto& r : replies_seen_[request]) {
        if (r.outcome() != SWARM_PLANNED && n++ == skip) {
          found = r;
          return true;
        }
      }
      return false;
    });
    if (!ok) ADD_FAILURE() << "no outcome of request " << request;
    return found;
  }
  std::vector<SwarmReply> replies(unsigned long long request) {
    std::lock_guard lock(mutex_);
    return replies_seen_[request];
  }

  SwarmStatus status(const std::function<bool(const SwarmStatus&)>& pred, const char* what) {
    return wait(status_seen_, pred, "the swarm status", what);
  }
  SwarmPlan plan(const std::function<bool(const SwarmPlan&)>& pred, const char* what) {
    return wait(plan_seen_, pred, "the swarm plan", what);
  }

  coordinator::CueFeed<RobotState>& state(const std::string& robot) {
    auto& f = states_[robot];
    if (!f) f = std::make_unique<coordinator::CueFeed<RobotState>>(participant_, robot + "/state");
    return *f;
  }

  // Waits until the robot reports working `job`; its state then.
  std::optional<RobotState> working(const std::string& robot, const std::string& job,
                                    std::chrono::seconds within) {
    auto& feed = state(robot);
    const auto until = std::chrono::steady_clock::now() + within;
    while (std::chrono::steady_clock::now() < until) {
      if (auto s = feed.latest(); s && s->job().id() == job) return s;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return std::nullopt;
  }

 private:
  template <class T>
  T wait(const std::optional<T>& seen, const std::function<bool(const T&)>& pred, const char* topic,
         const char* what) {
    using namespace std::chrono_literals;
    std::unique_lock lock(mutex_);
    if (!changed_.wait_for(lock, 30s, [&] { return seen && pred(*seen); })) {
      ADD_FAILURE() << topic << " never showed " << what;
    }
    return seen.value_or(T{});
  }

  DdsParticipant& participant_;
  std::string sender_;
  TopicWriter<SwarmRequest, SwarmRequestPubSubType> writer_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<unsigned long long, std::vector<SwarmReply>> replies_seen_;
  std::optional<SwarmStatus> status_seen_;
  std::optional<SwarmPlan> plan_seen_;
  unsigned long long next_id_ = 0;
  std::map<std::string, std::unique_ptr<coordinator::CueFeed<RobotState>>> states_;
  TopicReader<SwarmReply, SwarmReplyPubSubType> replies_;
  TopicReader<SwarmStatus, SwarmStatusPubSubType> status_;
  TopicReader<SwarmPlan, SwarmPlanPubSubType> plan_;
};

}  // namespace oscar::test
