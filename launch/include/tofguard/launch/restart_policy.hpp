#pragma once
// When to restart a crashed process: back-off doubling from an initial to a
// maximum delay, and giving up after too many restarts within a window (a
// process that keeps crashing is reported and left stopped). Pure: times are
// microseconds of the monotonic clock.
#include <cstdint>
#include <deque>
#include <optional>

namespace tofguard::launch {

struct RestartPolicy {
  int64_t initial_delay_us = 0;
  int64_t max_delay_us = 0;
  int max_restarts = 0;
  int64_t window_us = 0;
};

class RestartTracker {
 public:
  explicit RestartTracker(const RestartPolicy& policy) : policy_(policy) {}

  // The process exited at now_us: the delay before the next start, or
  // nullopt when it has been restarted max_restarts times within the window
  // already (give up).
  std::optional<int64_t> on_exit(int64_t now_us);
  // Restarts within the window, as of the last on_exit.
  int recent_restarts() const { return static_cast<int>(restarts_us_.size()); }

 private:
  RestartPolicy policy_;
  std::deque<int64_t> restarts_us_;
};

}  // namespace tofguard::launch
