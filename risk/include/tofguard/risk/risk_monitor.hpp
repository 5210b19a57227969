#pragma once
// tofguard-risk's logic without LCM or clocks inside: the caller passes
// each valid arrival with its monotonic time `now_us` (monotonic_us()), and
// RiskMonitor turns frames into risk_t verdicts. It composes four parts:
//
//   InputDeadlines  (input_deadlines.hpp)  the staleness of every input;
//   EstimateGate    (estimate_gate.hpp)    the wait for a frame's motion
//                                          estimate, which may rename a
//                                          model mismatch's cause;
//   PlanMonitor     (plan_monitor.hpp)     the arm leaving its plan;
//   SequentialEvidence (sequential_evidence.hpp) the CUSUMs on the frames'
//                                          evidence: calibration and joint
//                                          errors;
//   DecisionRule    (decision_rule.hpp)    debounce into WARNING/DANGEROUS,
//                                          the open diagnosis (hysteresis).
//
// Each frame is classified once, when it arrives: the frame rules
// (classify_frame) and, when they find nothing, the plan rule, both with the
// joint state of the frame's capture time (the newest at or before its
// utime), so a replayed log is judged the same however late a frame is
// processed. The gate then holds it (or not) and may rename its cause. The
// frames are then judged in frame order: the sequential evidence tests take
// the frame's evidence (a crossed test replaces any finding but a sensor or
// component fault's), the decision rule debounces the verdicts and keeps a
// diagnosis open, and an input deadline that has expired by the time of the
// verdict makes it DANGEROUS.
// docs/safety-chain.md gives every rule.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/risk/decision_rule.hpp"
#include "tofguard/risk/estimate_gate.hpp"
#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/risk/input_deadlines.hpp"
#include "tofguard/risk/joint_states_by_utime.hpp"
#include "tofguard/risk/plan_monitor.hpp"
#include "tofguard/risk/sequential_evidence.hpp"
#include "tofguard/risk/speed_limit.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

class RiskMonitor {
 public:
  // `channels` name the inputs in the verdicts' details; `camera_rate_hz`
  // (camera.rate_hz) sets the evidence tests' threshold. The deadlines run
  // from `start_us` (monotonic).
  RiskMonitor(const RiskSettings& settings, const ChannelNames& channels, robot_model::KinematicTree robot,
              double camera_rate_hz, int64_t start_us);

  // Arrivals of valid messages.
  void on_depth(int64_t now_us) { deadlines_.on_depth(now_us); }
  // A joint state not newer (utime) than the newest one taken — a duplicate,
  // one out of order, a driver's clock set back — is refused: it neither
  // feeds the joint-state deadline nor the record (a driver stuck resending
  // its last state must go stale, fault injection). Once the stream has
  // gone stale (the arm stopped on it) the next state other than a copy of
  // the newest starts it afresh.
  // Returns "" when taken, else why not (the caller counts and reports it).
  std::string on_joint_state(const joint_state_t& state, int64_t now_us);
  void on_camera_pose(int64_t now_us) { deadlines_.on_camera_pose(now_us); }
  void on_heartbeat(const heartbeat_t& heartbeat, int64_t now_us) {
    deadlines_.on_heartbeat(heartbeat.process, now_us);
  }
  // A plan that passed check_planned_trajectory and check_joint_names.
  void on_plan(const planned_trajectory_t& plan) { plan_.on_plan(plan); }

  // A frame arrives: the verdicts ready now, in frame order (none while
  // this frame or one before it waits for its estimate).
  //
  // Frames must come newer than the last one judged, in both seq and utime:
  // a duplicate or an older seq (a replayed or repeated message) and a
  // camera clock set back (seq up, utime down) are refused — no verdict,
  // the discrepancy deadline not fed, counted in refused_frames() with
  // last_refusal() saying why. Exceptions: an unusable frame never judged
  // before (a frame whose rendering timed out is published after newer
  // ones) is judged, since it can only stop the arm; and once the
  // discrepancy stream has gone stale (the arm stopped on it) the next
  // frame not judged before starts the stream afresh (a restarted camera,
  // a clock set back).
  std::vector<risk_t> on_frame(const discrepancy_t& frame, int64_t now_us);
  int64_t refused_frames() const { return refused_frames_; }
  // The speed limit for the arm's controller at `frame` (speed_limit.hpp),
  // with the arm's speed bound from the joint state at its capture.
  speed_limit_t speed_limit(const discrepancy_t& frame) const;
  // The wheelchair's occupant: its body regions' rules (body_region_rules
  // .hpp, with the arm's moving mass from its URDF) set the speed limit
  // too, and a frame whose arm is faster than a region's limit is an
  // UNKNOWN_OBJECT finding naming the region (debounced as the others);
  // a frame that shows the user missing from the model's place
  // (user_presence.hpp) stops the arm as an unclassified finding. Throws robot_model::ModelError for an arm
  // without masses.
  void set_occupant(const OccupantSettings& occupant);
  const std::string& last_refusal() const { return last_refusal_; }
  // A valid estimate (check_motion_estimate, this camera, the robot's
  // joints): the verdicts it releases.
  std::vector<risk_t> on_estimate(const motion_estimate_t& estimate, int64_t now_us);
  // The verdicts of frames whose wait for an estimate has ended by now_us.
  std::vector<risk_t> release_due(int64_t now_us);
  size_t waiting_frames() const { return gate_.waiting_frames(); }
  const SequentialEvidence& evidence() const { return evidence_; }
  // Several cameras: the joints' tests pooled over every camera's frames
  // (docs/safety-chain.md, "Several cameras: joint evidence summed"),
  // shared by every camera's monitor and outliving them; null: none. Each
  // frame this monitor judges goes into it as into its own tests; when it
  // crosses, this frame's verdict is the stop, and a diagnosis stays open
  // until the pooled tests are quiet and cleared too.
  void set_pooled_evidence(SequentialEvidence* pooled) { pooled_ = pooled; }
  bool diagnosis_open() const { return decision_.diagnosis_open(); }

  using EstimateStats = EstimateGate::Stats;
  const EstimateStats& estimate_stats() const { return gate_.stats(); }

  // The first expired deadline as a timeout verdict (seq -1, utime of the
  // last judged frame), or nothing while every input is fresh.
  std::optional<risk_t> check_deadlines(int64_t now_us) const;

  // "" or the first of `names` (field `field`) that is not a moving joint
  // of the robot's URDF.
  std::string check_joint_names(const std::vector<std::string>& names,
                                const std::string& field = "name") const;
  std::string check_joint_names(const joint_state_t& state) const { return check_joint_names(state.name); }

 private:
  // The frame's finding on arrival (frame rules, else the plan rule).
  ClassifiedFrame classify(const discrepancy_t& frame) const;
  // The verdicts of frames the gate released, in order.
  std::vector<risk_t> judge(std::vector<ClassifiedFrame> released, int64_t now_us);
  // A frame's evidence into the sequential tests (own and pooled): a
  // crossing replaces `finding`, a warning a finding of nothing.
  EvidenceStep weigh_evidence(const discrepancy_t& frame, FrameFinding* finding);
  // The sequential tests a diagnosis of `latched` may close on: quiet, and
  // `latched`'s fault shown gone (own tests and pooled).
  bool evidence_clean(const std::string& latched) const;

  const RiskSettings settings_;
  ClassifierContext classifier_context_;  // channel names; arm_moving set per frame
  robot_model::KinematicTree robot_;
  InputDeadlines deadlines_;
  JointStatesByUtime joint_states_;
  PlanMonitor plan_;
  EstimateGate gate_;
  SequentialEvidence evidence_;
  SequentialEvidence* pooled_ = nullptr;
  DecisionRule decision_;
  // T_r of the protective fields, s (chain_response_time_s).
  double response_time_s_ = 0;
  // The occupant's rules (set_occupant); empty without one.
  std::vector<BodyRegionRule> body_region_rules_;
  std::optional<OccupantSettings> occupant_;
  int64_t last_frame_utime_ = 0;
  // The newest frame taken in order (seq, utime) and the seqs judged lately.
  bool any_frame_ = false;
  int64_t newest_seq_ = 0;
  int64_t newest_utime_ = 0;
  std::deque<int64_t> judged_seqs_;
  int64_t refused_frames_ = 0;
  std::string last_refusal_;
};

}  // namespace tofguard::risk
