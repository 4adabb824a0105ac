#pragma once
// The coordinator's line to the robots of one module: proposals, commits and aborts go out in the
// order they were posted (a commit never overtakes its proposal), through the module's
// configuration topic, on a thread of its own so that a slow robot holds up nobody else. Safety
// monitors hear the world through it the same way.

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <variant>

#include <oscar/swarm.h>

#include "oscar/config_client.hpp"

namespace oscar::coordinator {

class RobotLink {
 public:
  /// A robot's answer to a proposal: ACK, NAK (`reason`), or none within the timeout (`silent`).
  struct Answer {
    std::string robot;
    unsigned long long transaction = 0;
    bool ack = false;
    bool silent = false;
    std::string reason;
  };
  using OnAnswer = std::function<void(Answer)>;

  RobotLink(ConfigClient& client, std::string module, std::chrono::milliseconds timeout,
            OnAnswer on_answer);
  ~RobotLink();
  RobotLink(const RobotLink&) = delete;
  RobotLink& operator=(const RobotLink&) = delete;

  void propose(Trajectory trajectory);
  void commit(const std::string& robot, unsigned long long transaction);
  void abort(const std::string& robot, unsigned long long transaction);
  /// Tells a safety monitor of this module the world (command `world`); a refusal or silence is
  /// logged (the monitor keeps the world it had).
  void tell_world(const std::string& monitor, SwarmWorld world);

  /// Asks the robot now, on the caller's thread, what it has committed (command `committed`):
  /// the answer's text, a Trajectory in YAML (oscar/swarm_yaml.hpp).
  /// @throws std::invalid_argument when the robot or its module refuses the command;
  ///         std::runtime_error when no answer comes within the timeout.
  std::string committed(const std::string& robot);

 private:
  struct Decision {
    std::string name;  // "commit" or "abort"
    TransactionDecision decision;
  };
  struct WorldNews {
    std::string monitor;
    SwarmWorld world;
  };
  using Message = std::variant<Trajectory, Decision, WorldNews>;
  void post(Message m);
  void run();
  void send(const Trajectory& t);
  void send(const Decision& d);
  void send(const WorldNews& w);

  ConfigClient& client_;
  std::string module_;
  std::chrono::milliseconds timeout_;
  OnAnswer on_answer_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Message> queue_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace oscar::coordinator
