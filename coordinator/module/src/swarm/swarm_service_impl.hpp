#pragma once
// SwarmService's implementation (not installed; docs/swarm.md, "The live swarm"): the service's
// state and the events that change it, handled one at a time on its thread (run()). Its
// definitions are in three files:
//  - swarm_service.cpp: construction, start and stop, the run loop, the status, and requests and
//    their transactions (planned, proposed to the robots, committed, planned again or given up);
//  - swarm_robots.cpp: robots joining planning and leaving it (broken down or silent), their jobs
//    placed again, and the history forgotten;
//  - swarm_world_changes.cpp: the world as the planner and the safety monitors get it, and its
//    changes at run time.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "live_world.hpp"
#include "oscar/config_client.hpp"
#include "oscar/coordinator/cue_feed.hpp"
#include "oscar/coordinator/swarm_service.hpp"
#include "oscar/swarm_types.hpp"
#include "oscar/topic_io.hpp"
#include "robot_link.hpp"
#include "swarm_wire.hpp"

namespace oscar::coordinator {

using swarm::TransactionId;

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

  // ---- running (swarm_service.cpp) ----

  Impl(SwarmSetup s, DdsParticipant& p);
  static swarm::SchedulerSettings with_present(swarm::SchedulerSettings s, double now);
  // Queues an event for the run loop (from any thread).
  void post(Event e);
  // The link to a module's command port, made the first time it is asked for.
  RobotLink& link_to(const std::string& module);
  void start();
  void stop();
  // The service's thread: the events in batches, then what is due (the world, the status, the
  // plan, the history).
  void run();

  // ---- requests (swarm_service.cpp) ----

  void reply(const Request& r, SwarmOutcome outcome, TransactionId tx, std::string reason,
             const std::vector<swarm::Job>& jobs = {});
  // A request arrives: planned, or held behind a world change.
  void handle(const SwarmRequest& message);
  // Plans the held requests in order, until a world change meets open transactions.
  void release_held();
  // True for a world change (add or remove obstacles).
  static bool changes_world(const SwarmRequest& m);
  // How many jobs a request submits (for the counters).
  static std::uint64_t jobs_in(const SwarmRequest& m);
  // Plans a request and proposes its transaction, or tells its requester why not.
  void plan(const std::shared_ptr<Request>& r);
  // Asks the robots a transaction changes; it commits when they all acknowledged.
  void propose(const std::shared_ptr<Request>& r, TransactionId tx, std::vector<swarm::Job> jobs,
               std::vector<swarm::Job> displaced);
  // A robot's answer: the transaction commits once all acknowledged; a NAK or silence aborts it
  // and the request is planned again, up to setup.replan_attempts times.
  void handle(const RobotLink::Answer& a);
  // A transaction commits: the robots and the requester hear it, a world change's world becomes
  // the world, and the jobs it displaced are placed again.
  void finish(TransactionId tx, const Pending& p);
  // A request that cannot be planned (any more): its requester hears why; a set that a
  // broken-down robot left short and that cannot be whole again ends.
  void give_up(const Request& r, SwarmOutcome outcome, TransactionId tx, const std::string& reason);
  // All or nothing for a set whose lost members cannot be placed again: its members not started
  // are unscheduled (a transaction the robots holding them are asked for, as any), and then its
  // requester hears ABORTED, naming the robot and the set.
  void end_set(const Request& r, const std::string& why);

  // ---- status (swarm_service.cpp) ----

  // Writes the status on oscar/swarm/status and keeps it for status().
  void publish_status(std::int64_t now);

  // ---- robots (swarm_robots.cpp) ----

  // Each robot's latest state: one that is up joins planning, one broken down or silent leaves it.
  void watch_robots(std::int64_t now);
  // A robot joins planning with what it has committed: idle where it stands, or (after this
  // coordinator restarted) driving the trajectory and working the jobs its predecessor
  // committed, which the planner takes over as they are.
  void add(Robot& robot, const RobotState& s, std::int64_t now);
  // A robot's answer to `committed` in the planner's terms; the present moves on to the
  // robot's time of answering if that is later.
  swarm_wire::CommittedPlan take_over(const std::string& id, const std::string& answer);
  // Where a job taken over from a robot's committed plan came from, to place it again when the
  // robot breaks down: its requester is not known, so the coordinator stands in for it.
  std::shared_ptr<Request> taken_over_request(const swarm::Job& j) const;
  // "j1, j2" for a log line.
  static std::string job_ids(const std::vector<swarm::Job>& jobs);
  // A robot leaves planning: its open transactions abort and go again, its jobs go to others.
  void lose(Robot& robot, const RobotState& s, const std::string& why);
  // The requests that place `jobs` again (removed from a robot that broke down, or displaced by
  // a changed world), after those in `again`: a single job alone, in its original window; the
  // lost members of a set together, within the set, once per set.
  std::vector<std::shared_ptr<Request>> requests_to_place(
      const std::vector<swarm::Job>& jobs, const std::string& cause,
      std::vector<std::shared_ptr<Request>> again);
  // True if one of `planned` places the lost members of `set` again or ends the set.
  bool handles_set(const std::vector<std::shared_ptr<Request>>& planned,
                   const std::string& set) const;
  // What ended more than a minute ago is history: the planner and the origins forget it.
  void forget_history();

  // ---- the world (swarm_world_changes.cpp) ----

  // How often loops are unrolled again and the monitors told the world again (a monitor that
  // restarted has only its parameters).
  static constexpr std::chrono::seconds kWorldAgain{30};

  // The world of the system file's obstacles.
  static LiveWorld live_world(const std::vector<SwarmObstacle>& obstacles);
  // The planner's world from just before `now` until loops must be unrolled again.
  static swarm::World planned(const LiveWorld& w, const swarm_wire::Clock& clock, double now);
  // Tells each safety monitor the world (command `world`).
  void tell_monitors();
  // A world change is planned when no transaction is open: nodes that run into the new world
  // after the frozen horizon are planned again in one transaction (Scheduler::change_world), and
  // the world is the new one once it commits. Obstacles added count from the frozen horizon on.
  void plan_world(const std::shared_ptr<Request>& r);
  // Loops are unrolled for a span ahead: before the present gets near its end they are
  // unrolled again (a world change that changes nothing else), and the monitors hear the world.
  void renew_world();
};

}  // namespace oscar::coordinator
