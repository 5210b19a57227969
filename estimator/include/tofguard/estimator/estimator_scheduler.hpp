#pragma once
// Which camera frames tofguard-estimator estimates and with what reported
// values (EstimatorScheduler): its logic apart from LCM and threads.
//
// Triggers (config `estimator`, docs/estimator.md), on the messages as
// published (the estimator runs none of tofguard-risk's rules):
//   TRIGGER_WARNING  a frame whose discrepancy_t (SAFETY_DISCREPANCY) is
//                    usable and reaches warning.mismatch_fraction or
//                    warning.p95_abs_dis_mm, or whose risk_t verdict
//                    (SAFETY_RISK) is WARNING or DANGEROUS with a model-
//                    mismatch cause (is_model_mismatch), as soon as both the
//                    frame and the trigger are in; at most one frame per
//                    warning.min_interval_ms of camera time;
//   TRIGGER_PERIODIC the newest frame every periodic_period_ms.
// A frame is estimated once, jointly with up to frames_per_estimate - 1
// kept frames just before it (MotionEstimator::estimate(frames)) that are
// on the same side of a fault's onset: for a frame whose discrepancy passed
// the warning level, earlier frames whose discrepancy passed it too; for
// any other frame, earlier frames whose discrepancy did not (or has not
// come). An offset that began between two frames is not averaged with the
// frames before it. The
// joints and the camera pose are the robot's state at each frame's utime
// (robot_state::StateHistory, with the renderer's limits: JOINT_STATE
// interpolated, CAMERA_POSE else the config's static pose).
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/estimator/estimate_message.hpp"
#include "tofguard/estimator/motion_estimator.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tofguard/robot_state/state_history.hpp"
#include "tofguard/settings/estimator_settings.hpp"

namespace tofguard::estimator {

struct EstimateJob {
  // frames[0] is the frame the estimate is about, the others the frames
  // just before it (newest first).
  std::vector<EstimatorFrame> frames;
  EstimateContext context;
};

// A frame to estimate, or an estimate that could not even be started.
struct ScheduledWork {
  std::optional<EstimateJob> job;
  std::optional<motion_estimate_t> unusable;
};

class EstimatorScheduler {
 public:
  EstimatorScheduler(const EstimatorProcessSettings& settings, const robot_model::SceneModel& scene);

  // False (ignored) for another robot's state or one not newer than the
  // last.
  bool on_joint_state(const joint_state_t& state);
  void on_camera_pose(const camera_pose_t& pose);
  // Frames of other cameras, and frames the camera's profile
  // (settings.camera_profile) does not fit, are ignored (false); the others
  // are kept corrected by the profile.
  bool on_depth(const depth_image_t& frame);
  void on_discrepancy(const discrepancy_t& discrepancy);
  // tofguard-risk's verdict (check_risk passed): a model mismatch on a
  // frame makes it a warning frame like a discrepancy past the warning
  // level. Timeouts (seq -1), SAFE and fault verdicts change nothing.
  void on_risk(const risk_t& risk);
  // Asks for the newest frame (periodic trigger).
  void request_newest();
  // The work that became ready (frame and trigger both in), oldest first.
  std::vector<ScheduledWork> take_ready();

  // Frames whose discrepancy asked for an estimate but which left the
  // window before (or never arrived).
  int64_t missed() const { return missed_; }

 private:
  ScheduledWork build(const depth_image_t& frame, int8_t trigger) const;
  // The discrepancy passed the warning level (estimator.warning).
  bool passes_warning(const discrepancy_t& d) const;
  // Frame `seq` (captured at `utime`) is a warning frame: estimate it
  // (rate limited), now or once it is in.
  void on_warning(int64_t seq, int64_t utime);
  // The frame with its reported joints and camera pose (for `context`'s
  // camera frame_id), or "" and the reason it cannot be estimated.
  std::optional<EstimatorFrame> estimator_frame(const depth_image_t& frame, const std::string& frame_id,
                                                std::string* why) const;

  EstimatorProcessSettings settings_;
  const robot_model::SceneModel& scene_;
  robot_state::StateHistory state_;
  std::map<int64_t, depth_image_t> frames_;  // by seq
  std::map<int64_t, int8_t> wanted_;         // seq -> trigger
  std::set<int64_t> estimated_;
  std::set<int64_t> warning_seqs_;  // kept frames that passed the warning level (discrepancy or risk)
  int64_t last_warning_utime_ = 0;  // utime of the last warning-triggered frame
  std::vector<ScheduledWork> ready_;
  int64_t missed_ = 0;
};

}  // namespace tofguard::estimator
