#pragma once
// ReadingPriority: the reading thread of a replay reads at background priority (SCHED_IDLE)
// while it is ahead, so that a lane waking to publish takes the CPU from it at once; on a busy
// 2-core machine its bursts (a chunk read, checked and copied) otherwise held lanes up for
// milliseconds (docs/benchmarks.md). Only where the thread may be raised again when it falls
// behind: root with CAP_SYS_NICE, or an RLIMIT_NICE of 20 or more (`ulimit -e`). Elsewhere it
// stays at normal priority, since an idle-priority reader would starve on a saturated machine.

#include <sched.h>
#include <sys/types.h>

namespace oscar::replay {

class ReadingPriority {
 public:
  /// For the calling thread; finds out whether it may go back from SCHED_IDLE to its present
  /// scheduling (e.g. SCHED_FIFO under `chrt -f`).
  ReadingPriority();
  ~ReadingPriority();  ///< back to the scheduling it had
  ReadingPriority(const ReadingPriority&) = delete;
  ReadingPriority& operator=(const ReadingPriority&) = delete;

  bool available() const { return available_; }
  /// Far ahead: background priority. Any thread may call these.
  void background() const;
  /// Falling behind: the scheduling it had.
  void normal() const;

 private:
  pid_t tid_;
  int policy_;
  sched_param param_{};
  bool available_ = false;
};

}  // namespace oscar::replay
