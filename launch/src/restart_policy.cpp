#include "tofguard/launch/restart_policy.hpp"

#include <algorithm>

namespace tofguard::launch {

std::optional<int64_t> RestartTracker::on_exit(int64_t now_us) {
  while (!restarts_us_.empty() && now_us - restarts_us_.front() > policy_.window_us) {
    restarts_us_.pop_front();
  }
  if (static_cast<int>(restarts_us_.size()) >= policy_.max_restarts) return std::nullopt;
  // The n-th restart within the window waits initial * 2^n, at most max.
  int64_t delay_us = policy_.initial_delay_us;
  for (size_t i = 0; i < restarts_us_.size() && delay_us < policy_.max_delay_us; ++i) delay_us *= 2;
  restarts_us_.push_back(now_us);
  return std::min(delay_us, policy_.max_delay_us);
}

}  // namespace tofguard::launch
