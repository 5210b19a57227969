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
//
// Motion estimates (docs/safety-chain.md, "Using the motion estimate"): with
// risk.estimate.enabled, a frame whose discrepancy finding is a model
// mismatch (JOINT_ERROR, CALIBRATION_ERROR, UNKNOWN_OBJECT, UNCLASSIFIED)
// waits at most risk.estimate.wait_ms from its arrival for the estimate of
// its seq; frames behind it wait with it, so verdicts keep frame order and
// the debounce counts frames in order. The estimate may name the cause, the
// suspect and the detail; it never makes a frame safer.
//
// The plan (risk.plan): a joint state inside the plan's time span that is
// further from the plan than risk.plan.max_deviation_* is "the arm left its
// plan", a finding of the frames judged while it is the newest joint state
// (when no other rule applies).
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/risk/robot_tree.hpp"
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/risk/risk_settings.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/common/planned_trajectory.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::risk {

class RiskMonitor {
 public:
  // `channels` name the inputs in the verdicts' details.
  RiskMonitor(const RiskSettings& settings, const ChannelNames& channels, RobotTree robot, int64_t start_us);

  // Arrivals of valid messages.
  void on_depth(int64_t now_us);
  void on_joint_state(const joint_state_t& state, int64_t now_us);
  void on_camera_pose(int64_t now_us);
  void on_heartbeat(const heartbeat_t& heartbeat, int64_t now_us);

  // A plan that passed check_planned_trajectory and check_joint_names.
  void on_plan(const planned_trajectory_t& plan);

  // The verdict on one frame (its utime and seq), judged now, without
  // waiting for an estimate (one already received for the frame is used).
  // An expired deadline makes it DANGEROUS with that deadline's cause;
  // otherwise the frame's finding, WARNING until it has held for the
  // debounce count, then DANGEROUS.
  risk_t on_discrepancy(const discrepancy_t& frame, int64_t now_us);

  // A frame arrives: the verdicts ready now, in frame order (none while
  // this frame or one before it waits for its estimate).
  std::vector<risk_t> on_frame(const discrepancy_t& frame, int64_t now_us);
  // A valid estimate (check_motion_estimate, this camera, the robot's
  // joints): the verdicts it releases.
  std::vector<risk_t> on_estimate(const motion_estimate_t& estimate, int64_t now_us);
  // The verdicts of frames whose wait for an estimate has ended by now_us.
  std::vector<risk_t> release_due(int64_t now_us);
  size_t waiting_frames() const { return waiting_.size(); }

  struct EstimateStats {
    int64_t received = 0;
    int64_t used = 0;            // named a frame's cause
    int64_t explained_nothing = 0;  // received in time, no finding (discrepancy rules judged)
    int64_t missing = 0;         // a waiting frame's wait ended without one
    int64_t late = 0;            // arrived after its frame was judged
  };
  const EstimateStats& estimate_stats() const { return estimate_stats_; }

  // The first expired deadline as a timeout verdict (seq -1, utime of the
  // last frame), or nothing while every input is fresh.
  std::optional<risk_t> check_deadlines(int64_t now_us) const;

  // "" or the first of `names` (field `field`) that is not a moving joint
  // of the robot's URDF.
  std::string check_joint_names(const std::vector<std::string>& names, const std::string& field = "name") const;
  std::string check_joint_names(const joint_state_t& state) const { return check_joint_names(state.name); }

 private:
  struct Deadline {
    std::string what;   // channel or process name
    int8_t cause;       // risk_t::CAUSE_*
    int64_t limit_us;
    int64_t last_us;    // last arrival (or the start)
    bool ever = false;  // anything arrived yet
  };
  struct WaitingFrame {
    discrepancy_t frame;
    bool wants_estimate = false;
    int64_t wait_until_us = 0;
  };
  std::optional<FrameFinding> expired(int64_t now_us) const;
  // The frame's verdict now (no deadline touched).
  risk_t judge(const discrepancy_t& frame, int64_t now_us, bool waited);
  // True when the frame's discrepancy finding is a model mismatch and
  // estimates are in use.
  bool wants_estimate(const discrepancy_t& frame) const;
  FrameFinding discrepancy_finding(const discrepancy_t& frame) const;
  // The estimate of `frame` itself; with or_older, else the newest of an
  // earlier frame of the same camera at most risk.estimate_max_age_ms older.
  const motion_estimate_t* estimate_for(const discrepancy_t& frame, bool or_older) const;
  std::vector<risk_t> release(int64_t now_us);
  // The arm left its plan at `utime`: the joint state at that time
  // (joint_state_at) against the plan at the joint state's utime.
  std::optional<FrameFinding> plan_deviation_at(int64_t utime) const;
  static void touch(Deadline* d, int64_t now_us);

  const RiskSettings settings_;
  const ChannelNames channels_;
  RobotTree robot_;
  Deadline depth_;
  Deadline discrepancy_;
  Deadline joint_state_;
  Deadline camera_pose_;
  std::map<std::string, Deadline> heartbeats_;
  PlannedTrajectory plan_;
  std::deque<WaitingFrame> waiting_;
  std::deque<motion_estimate_t> estimates_;  // the newest few, by arrival
  std::deque<int64_t> judged_seqs_;          // the newest few judged frames
  EstimateStats estimate_stats_;
  // The joint states by utime (ascending; the last 2 s): the frozen-image
  // and plan rules ask about the frame's capture time, not about whichever
  // joint state arrived last, so that a replayed log is judged the same on
  // every run however late the frame is processed. joint_state_at: the
  // newest at or before `utime` (the oldest for an older frame), nullptr
  // when there is none.
  const joint_state_t* joint_state_at(int64_t utime) const;
  bool arm_moving_at(int64_t utime) const;
  std::deque<joint_state_t> joint_states_by_utime_;
  int consecutive_ = 0;
  int64_t last_frame_utime_ = 0;
};

}  // namespace tofguard::risk
