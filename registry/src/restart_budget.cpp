#include "restart_budget.hpp"

namespace oscar::internal {

int RestartBudget::within(Clock::time_point now, Clock::duration window) {
  // Older restarts will never count again: forgetting them keeps the record as short as `max`.
  while (!restarts_.empty() && now - restarts_.front() >= window) restarts_.pop_front();
  return static_cast<int>(restarts_.size());
}

bool RestartBudget::allows(Clock::time_point now, int max, Clock::duration window) {
  return within(now, window) < max;
}

}  // namespace oscar::internal
