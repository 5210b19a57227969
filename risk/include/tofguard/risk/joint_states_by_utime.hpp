#pragma once
// The joint states of the last 2 s of utime, in utime order: the frozen-image
// and plan rules ask about a frame's capture time, not about whichever joint
// state arrived last, so that a replayed log is judged the same on every run
// however late a frame is processed.
#include <cstdint>
#include <deque>

#include "tofguard/joint_state_t.hpp"

namespace tofguard::risk {

class JointStatesByUtime {
 public:
  // Keeps the states whose utime is within `keep_us` of the newest.
  explicit JointStatesByUtime(int64_t keep_us = 2'000'000) : keep_us_(keep_us) {}

  // A joint state not newer than the newest kept one (out of order, or a
  // duplicate) is not added: the record stays sorted by utime. Returns
  // whether it was added.
  bool add(const joint_state_t& state);
  // The newest state's utime (-1 when none).
  int64_t newest_utime() const { return states_.empty() ? -1 : states_.back().utime; }
  // Forgets every state (a stream that starts afresh).
  void clear() { states_.clear(); }

  // The newest joint state taken at or before `utime`; for a frame older
  // than all of them, the oldest; nullptr when there is none.
  const joint_state_t* at(int64_t utime) const;

 private:
  int64_t keep_us_;
  std::deque<joint_state_t> states_;
};

}  // namespace tofguard::risk
