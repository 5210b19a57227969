#pragma once
// What the simulated arm's controller does with SAFETY_SPEED_LIMIT
// (joints_sim.follow_speed_limit; docs/security.md says what a real
// controller must do): it scales its motion's speed by a factor in [0, 1]
// so that its speed bound stays at most margin times the newest verified
// limit, and stands (0) once that limit has expired.
//
// The limit carries the arm's speed bound as tofguard-risk computed it from
// the joint state at the frame's capture (arm_speed_m_s, or -1 when it
// could not); divided by the scale that joint state moved at, it is the
// full-speed bound, the follower's gain. Pure logic: no LCM; times are the
// receiver's monotonic clock (limits) and the joint states' utimes (which
// scale a limit's arm_speed_m_s was computed at).
#include <cstdint>
#include <deque>
#include <utility>

#include "tofguard/speed_limit_t.hpp"

namespace tofguard::sim {

class SpeedLimitFollower {
 public:
  // margin in (0, 1]; ramp_per_s > 0: how fast the scale may rise, per s.
  SpeedLimitFollower(double margin, double ramp_per_s);

  // A joint state went out at `utime` moving at `scale`.
  void on_joint_state(int64_t utime, double scale);
  // A verified, checked limit arrived at `now_us` (monotonic).
  void on_limit(const speed_limit_t& limit, int64_t now_us);
  // The scale for the next `dt_s` of motion at `now_us`.
  double next_scale(int64_t now_us, double dt_s);

  double scale() const { return scale_; }

 private:
  // The scale of the newest joint state at or before `utime`; -1 if none
  // is kept.
  double scale_at(int64_t utime) const;

  double margin_;
  double ramp_per_s_;
  double scale_ = 0;
  // The newest limit: m/s, its expiry (monotonic us, -1: none yet).
  double limit_m_s_ = 0;
  int64_t limit_expires_us_ = -1;
  // The full-speed bound, m/s (-1: not known).
  double full_speed_bound_m_s_ = -1;
  // (utime, scale) of the joint states of the last 2 s.
  std::deque<std::pair<int64_t, double>> published_;
};

}  // namespace tofguard::sim
