#pragma once
// The staleness deadlines of tofguard-risk's inputs (docs/safety-chain.md,
// "Deadlines"): TOF_DEPTH, JOINT_STATE, CAMERA_POSE (only when required),
// the heartbeat of each required process, and SAFETY_DISCREPANCY.
//
// Time: every deadline is measured on the receiver's monotonic clock (the
// `now_us` the caller passes, from monotonic_us()) as the time since the
// last valid arrival; message utimes are never looked at, so a replayed log
// is judged like live data. Before anything has arrived a deadline runs from
// the start: a chain that never starts is stale, not safe.
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

class InputDeadlines {
 public:
  // Deadlines from risk.deadlines_ms (as read: microseconds), risk.camera_pose and
  // risk.required_heartbeats; `channels` names the watched inputs.
  InputDeadlines(const RiskSettings& risk, const ChannelNames& channels, int64_t start_us);

  // Valid arrivals at monotonic `now_us`.
  void on_depth(int64_t now_us) { touch(&depth_, now_us); }
  void on_joint_state(int64_t now_us) { touch(&joint_state_, now_us); }
  void on_camera_pose(int64_t now_us) { touch(&camera_pose_, now_us); }
  void on_discrepancy(int64_t now_us) { touch(&discrepancy_, now_us); }
  // A heartbeat of a process that is not required is ignored.
  void on_heartbeat(const std::string& process, int64_t now_us);

  // The first expired deadline in the documented order (depth, joint state,
  // camera pose, heartbeats by process name, discrepancy) as a finding:
  // its cause, suspect the channel or process, score its age and threshold
  // its limit in milliseconds; nothing while every input is fresh.
  std::optional<FrameFinding> first_expired(int64_t now_us) const;

  // Whether the joint-state / discrepancy stream has been silent past its
  // deadline (so the arm has been stopped on it): a stream that restarts
  // with older seqs or utimes (a restarted driver, a clock set back) may
  // then start afresh.
  bool joint_state_expired(int64_t now_us) const {
    return now_us - joint_state_.last_us > joint_state_.limit_us;
  }
  bool discrepancy_expired(int64_t now_us) const {
    return now_us - discrepancy_.last_us > discrepancy_.limit_us;
  }

 private:
  struct Deadline {
    std::string what;  // channel or process name
    int8_t cause = 0;  // risk_t::CAUSE_*
    int64_t limit_us = 0;
    int64_t last_us = 0;  // last arrival (or the start), monotonic
    bool ever = false;    // anything arrived yet
    bool heartbeat = false;
  };
  static void touch(Deadline* d, int64_t now_us);

  Deadline depth_;
  Deadline joint_state_;
  Deadline camera_pose_;
  bool camera_pose_required_;
  std::map<std::string, Deadline> heartbeats_;  // by process name: checked in that order
  Deadline discrepancy_;
};

}  // namespace tofguard::risk
