#pragma once
// tofguard-risk's state: the deadlines of its inputs and the debouncing of
// frame findings into risk_t verdicts.
//
// Time: every deadline is measured on the receiver's monotonic clock (the
// `now_us` the caller passes, from monotonic_us()) as the time since the
// last valid arrival; message utimes are only copied into the verdicts, so
// a replayed log is judged like live data. Before anything has arrived the
// deadlines run from the monitor's start: a chain that never starts is
// stale, not safe.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "frame_classifier.hpp"
#include "robot_tree.hpp"
#include "tofguard/config.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::risk {

class RiskMonitor {
 public:
  RiskMonitor(const Config& config, RobotTree robot, int64_t start_us);

  // Arrivals of valid messages.
  void on_depth(int64_t now_us);
  void on_joint_state(const joint_state_t& state, int64_t now_us);
  void on_camera_pose(int64_t now_us);
  void on_heartbeat(const heartbeat_t& heartbeat, int64_t now_us);

  // The verdict on one frame (its utime and seq). An expired deadline makes
  // it DANGEROUS with that deadline's cause; otherwise the frame's finding,
  // WARNING until it has held for the debounce count, then DANGEROUS.
  risk_t on_discrepancy(const discrepancy_t& frame, int64_t now_us);

  // The first expired deadline as a timeout verdict (seq -1, utime of the
  // last frame), or nothing while every input is fresh.
  std::optional<risk_t> check_deadlines(int64_t now_us) const;

  // "" or the joint names of a joint state not in the robot's URDF.
  std::string check_joint_names(const joint_state_t& state) const;

 private:
  struct Deadline {
    std::string what;   // channel or process name
    int8_t cause;       // risk_t::CAUSE_*
    int64_t limit_us;
    int64_t last_us;    // last arrival (or the start)
    bool ever = false;  // anything arrived yet
  };
  std::optional<FrameFinding> expired(int64_t now_us) const;
  static void touch(Deadline* d, int64_t now_us);

  const Config config_;
  RobotTree robot_;
  Deadline depth_;
  Deadline discrepancy_;
  Deadline joint_state_;
  Deadline camera_pose_;
  std::map<std::string, Deadline> heartbeats_;
  // Whether the arm moved, by joint-state utime (ascending; the last 2 s):
  // the frozen-image rule asks about the frame's capture time, not about
  // whichever joint state arrived last, so that a replayed log is judged
  // the same on every run however late the frame is processed.
  bool arm_moving_at(int64_t utime) const;
  std::deque<std::pair<int64_t, bool>> arm_moving_by_utime_;
  int consecutive_ = 0;
  int64_t last_frame_utime_ = 0;
};

}  // namespace tofguard::risk
