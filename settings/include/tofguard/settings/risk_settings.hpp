#pragma once
// tofguard-risk's settings (config section `risk`, docs/safety-chain.md):
// deadlines, thresholds and debouncing. Durations are integer microseconds,
// converted once when the file is read (YamlMap::milliseconds_as_us), so
// that every deadline check compares integers on the monotonic clock.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/auth/auth_settings.hpp"
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/yaml_reader.hpp"
#include "tofguard/settings/occupant_settings.hpp"

namespace tofguard::settings {

// The large-offset test's alternatives where risk.evidence leaves them out:
// well above the share of the alternative a commissioned camera's allowance
// takes where it covers the first test's (B / I above 3 deg on a quarter of
// the default arm's wrist frames), and half the naming search's range, within which the linear
// fit's reading still grows with the offset (docs/safety-chain.md, "A large
// offset").
constexpr double kDefaultLargeJointOffsetDeg = 10.0;
constexpr double kDefaultLargeJointOffsetM = 0.01;

struct RiskSettings {
  // check_period_ms: how often deadlines are checked (and timeouts
  // re-published); microseconds.
  int64_t check_period_us = 0;
  // deadlines_ms.{depth, discrepancy, joint_state, heartbeat} and
  // camera_pose.deadline_ms: staleness deadlines on the receiver's
  // monotonic clock (time since the last valid arrival); microseconds.
  int64_t depth_deadline_us = 0;
  int64_t discrepancy_deadline_us = 0;
  int64_t joint_state_deadline_us = 0;
  // camera_pose.required: CAMERA_POSE must keep coming.
  bool camera_pose_required = false;
  int64_t camera_pose_deadline_us = 0;
  int64_t heartbeat_deadline_us = 0;
  // required_heartbeats: processes (heartbeat_t.process) whose heartbeat
  // must keep coming.
  std::vector<std::string> required_heartbeats;
  // camera_loss (with several cameras): what a lost camera (its own
  // verdict a fault of the camera: stalled, frozen, silent, unusable,
  // moved) lets the arm do. "stop": stopped until that camera judges the
  // arm again. "continue_after_named_reset": stopped until an operator's
  // release naming the camera (camera_release_t, tofguard-reset
  // --release-camera) and a reset; then the remaining cameras judge alone,
  // every verdict saying which camera is left out, until it is back
  // (risk/verdict_fusion.hpp).
  bool continue_after_named_camera_release = false;
  // unseen_arm_max_fraction (with several cameras): a frame verdict whose
  // robot links seen by no camera (risk/arm_coverage.hpp) are more than
  // this fraction of the links counted is DANGEROUS (unclassified, suspect
  // risk.unseen_arm_max_fraction), 0..1.
  double unseen_arm_max_fraction = 0;
  // debounce_frames: a model mismatch (joint, calibration, object,
  // unclassified) is WARNING until it has held for this many consecutive
  // frames, then DANGEROUS.
  int debounce_frames = 0;
  // sensor_debounce_frames: the same for per-frame sensor faults (unusable
  // frame, invalid pixels, uncalibrated, frozen).
  int sensor_debounce_frames = 0;
  // sensor.*: sensor faults.
  double max_invalid_fraction = 0;
  bool calibrated_required = true;
  int frozen_repeat_frames = 0;
  double moving_joint_speed_rad_s = 0;
  // joint_error.* and calibration_error.*: classification
  // (docs/safety-chain.md).
  int min_link_pixels = 0;
  double link_mismatch_fraction = 0;
  // joint_error.link_missing_fraction.
  double joint_link_missing_fraction = 0;
  // joint_error.link_affected_{fraction, min_pixels}: a link on the way down
  // to the missing links counts as moved (and the joint above it is blamed)
  // when this fraction of it, and at least this many pixels, mismatch.
  double joint_link_affected_fraction = 0;
  int joint_link_affected_min_pixels = 0;
  int min_environment_pixels = 0;
  // calibration_error.environment_mismatch_fraction, robot_link_fraction.
  double calibration_environment_mismatch_fraction = 0;
  double calibration_robot_link_fraction = 0;
  // unknown_object_min_area_m2: the smallest area of unexplained surface
  // that counts as an object (square metres); its square root is the
  // detection capability that sizes field.intrusion_distance_m.
  double unknown_object_min_area_m2 = 0;
  // unclassified_blob_area_m2: the largest component of farther
  // mismatches (robot or environment missing) above which an unexplained
  // mismatch stops the arm (square metres).
  double unclassified_blob_area_m2 = 0;

  // field.*: the protective and warning fields (protective_field.hpp,
  // docs/safety-chain.md "Protective fields"): approach_speed_m_s K (m/s),
  // chain_latency_ms (a frame's capture to the stop output, us), the
  // robot's stopping_time_ms T_s (us) and stopping_distance_m S_s (m), the
  // intrusion_distance_m C (m; at least ISO 13855's for the detection
  // capability sqrt(unknown_object_min_area_m2)), and warning_margin_m
  // (the warning field's depth beyond S, m).
  double field_approach_speed_m_s = 0;
  int64_t field_chain_latency_us = 0;
  int64_t field_stopping_time_us = 0;
  double field_stopping_distance_m = 0;
  double field_intrusion_distance_m = 0;
  double field_warning_margin_m = 0;

  // estimate.*: the motion estimate (MOTION_ESTIMATE, docs/safety-chain.md):
  // a frame with a model mismatch waits at most estimate_wait (monotonic,
  // from its arrival; estimate.wait_ms) for the estimate of its seq, which
  // then names the cause. Microseconds.
  bool estimate_enabled = false;
  int64_t estimate_wait_us = 0;
  // estimate.max_age_ms: the estimator takes longer than a frame period on a
  // small CPU, so the newest estimate of an earlier frame of the same
  // camera, at most estimate_max_age older (camera utimes, not wall clock),
  // also serves a frame whose own estimate has not come: the frame does not
  // wait then. Fail safe either way: an estimate only renames a mismatch's
  // cause. Microseconds.
  int64_t estimate_max_age_us = 0;
  // A joint offset or camera correction is significant when it exceeds
  // estimate_sigmas times its 1-sigma uncertainty and the minimum.
  double estimate_sigmas = 0;
  double estimate_min_joint_offset_deg = 0;
  double estimate_min_joint_offset_m = 0;  // prismatic joints
  double estimate_min_translation_m = 0;
  double estimate_min_rotation_deg = 0;
  // Neither significant, yet the residual after the estimate is above this:
  // something the model lacks (an unknown object), millimetres.
  double estimate_unexplained_residual_mm = 0;

  // evidence.*: the sequential evidence tests on discrepancy_t's evidence
  // fields (docs/safety-chain.md, "Sequential evidence and its
  // thresholds"). false_stop_period_h: one false stop in this many hours of
  // nominal operation is allowed; with the number of hypotheses and the
  // camera rate it gives the CUSUM threshold h.
  double evidence_false_stop_period_h = 0;
  // The smallest faults to detect, each test's alternative: a joint offset
  // (joint_offset_deg, read in degrees, held in radians; joint_offset_m for
  // prismatic joints), a camera translation (camera_translation_m) along
  // any optical axis or a rotation about one (camera_rotation_deg, held in
  // radians).
  double evidence_joint_offset_rad = 0;
  double evidence_joint_offset_m = 0;
  // A joint's second test, at a large offset (large_joint_offset_deg, held
  // in radians, and large_joint_offset_m; optional, absent: 10 deg and
  // 10 mm; each above its joint_offset): where the static allowance covers
  // the first test's alternative, a large offset still shows beyond it
  // (docs/safety-chain.md, "A large offset").
  double evidence_large_joint_offset_rad = 0;
  double evidence_large_joint_offset_m = 0;
  double evidence_camera_translation_m = 0;
  double evidence_camera_rotation_rad = 0;
  // WARNING while some CUSUM is at or above this fraction of h.
  double evidence_warning_fraction = 0;
  // A diagnosis (a DANGEROUS verdict) stays open, its cause and suspect
  // latched, until this many consecutive frames have no finding at all.
  int evidence_clear_frames = 0;

  // plan.*: the plan (PLANNED_TRAJECTORY): a joint state inside the plan's
  // time span further than this from the plan at its utime is "the arm left
  // its plan" (degrees; metres for prismatic joints).
  bool plan_enabled = false;
  double plan_max_deviation_deg = 0;
  double plan_max_deviation_m = 0;
};

// Reads (and finishes) the `risk` section.
RiskSettings read_risk_settings(YamlMap section);

// Everything tofguard-risk needs.
// One camera tofguard-risk judges (config `camera`, or an entry of
// `cameras`).
struct RiskCamera {
  // camera.id: frames and estimates of another camera are rejected.
  std::string id;
  // camera.rate_hz: frames per second, for the evidence tests' threshold
  // (false stops per hour = hypotheses * frames per hour / e^h).
  double rate_hz = 0;
  // Its channels (camera_channel_names): its frames, depth images, pose and
  // estimates arrive on its own.
  ChannelNames channels;
  // risk.required_heartbeats as this camera's processes are named: a
  // process of one camera (common/process.hpp, per_camera_process_names)
  // with the camera's suffix.
  std::vector<std::string> required_heartbeats;
};

struct RiskProcessSettings {
  LcmSettings lcm;
  // The channels every camera shares (joint state, verdicts, heartbeats...).
  ChannelNames channels;
  // robot.urdf: the arm's kinematic tree (which joint moves which link).
  std::string robot_urdf_path;
  // With several cameras, each robot link's surface area for the unseen
  // arm's share (risk/arm_coverage.hpp) is read from the URDF's meshes:
  // robot.package_paths to find them, renderer.geometry ("visual" or
  // "collision") for the geometry the cameras' frames are compared with.
  std::vector<std::string> robot_package_paths;
  std::string rendered_geometry;
  // Every camera, in config order; each is judged on its own and the
  // verdicts are fused (risk/verdict_fusion.hpp).
  std::vector<RiskCamera> cameras;
  // With a key every verdict also goes out signed on channels.risk_auth
  // (the only risk stream a keyed tofguard-intervene trusts).
  auth::AuthSettings auth;
  RiskSettings risk;
  // The wheelchair's occupant (absent: none): its body regions' rules set
  // the speed limit beside the protective field's (docs/safety-chain.md,
  // "The user").
  std::optional<OccupantSettings> occupant;
};

// The intrusion distance C that ISO 13855 requires for a detection
// capability of `detection_capability_m` (the smallest object always
// detected), m: 8 * (d - 14 mm) for d <= 40 mm (not below 0), 0.85 m
// beyond (a reach of the arm).
double iso13855_intrusion_distance_m(double detection_capability_m);

}  // namespace tofguard::settings

// The component's own names for its settings (tofguard::risk::RiskSettings, ...).
namespace tofguard::risk {
using settings::iso13855_intrusion_distance_m;
using settings::read_risk_settings;
using settings::RiskCamera;
using settings::RiskProcessSettings;
using settings::RiskSettings;
}  // namespace tofguard::risk
