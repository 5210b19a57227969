#include "tofguard/risk/joint_states_by_utime.hpp"

namespace tofguard::risk {

bool JointStatesByUtime::add(const joint_state_t& state) {
  if (!states_.empty() && state.utime <= states_.back().utime) return false;
  states_.push_back(state);
  while (states_.front().utime < state.utime - keep_us_) states_.pop_front();
  return true;
}

const joint_state_t* JointStatesByUtime::at(int64_t utime) const {
  for (auto it = states_.rbegin(); it != states_.rend(); ++it) {
    if (it->utime <= utime) return &*it;
  }
  return states_.empty() ? nullptr : &states_.front();
}

}  // namespace tofguard::risk
