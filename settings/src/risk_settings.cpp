#include "tofguard/settings/risk_settings.hpp"

#include <algorithm>
#include <cmath>

namespace tofguard::settings {

namespace {

// risk.deadlines_ms: each input stream's deadline.
void read_deadlines(YamlMap deadlines, RiskSettings* r) {
  r->depth_deadline_us = deadlines.milliseconds_as_us("depth", 1, 60000);
  r->discrepancy_deadline_us = deadlines.milliseconds_as_us("discrepancy", 1, 60000);
  r->joint_state_deadline_us = deadlines.milliseconds_as_us("joint_state", 1, 60000);
  r->heartbeat_deadline_us = deadlines.milliseconds_as_us("heartbeat", 1, 60000);
  deadlines.finish();
}

// risk.camera_pose: whether CAMERA_POSE is required, and its deadline.
void read_camera_pose(YamlMap pose, RiskSettings* r) {
  r->camera_pose_required = pose.boolean("required");
  r->camera_pose_deadline_us = pose.milliseconds_as_us("deadline_ms", 1, 600000);
  pose.finish();
}

// risk.sensor: the sensor-fault rules.
void read_sensor(YamlMap sensor, RiskSettings* r) {
  r->max_invalid_fraction = sensor.number("max_invalid_fraction", 0, 1);
  r->calibrated_required = sensor.boolean("calibrated_required");
  r->frozen_repeat_frames = static_cast<int>(sensor.integer("frozen_repeat_frames", 1, 1000));
  r->moving_joint_speed_rad_s = sensor.number("moving_joint_speed_rad_s", 0, 100);
  sensor.finish();
}

// risk.joint_error: the joint-error rule.
void read_joint_error(YamlMap joint, RiskSettings* r) {
  r->min_link_pixels = static_cast<int>(joint.integer("min_link_pixels", 1, 1000000));
  r->link_mismatch_fraction = joint.number("link_mismatch_fraction", 0.01, 1);
  r->joint_link_missing_fraction = joint.number("link_missing_fraction", 0.01, 1);
  r->joint_link_affected_fraction = joint.number("link_affected_fraction", 0.001, 1);
  r->joint_link_affected_min_pixels = static_cast<int>(joint.integer("link_affected_min_pixels", 1, 100000));
  joint.finish();
}

// risk.calibration_error: the calibration-error rule.
void read_calibration_error(YamlMap calibration, RiskSettings* r) {
  r->min_environment_pixels = static_cast<int>(calibration.integer("min_environment_pixels", 1, 100000000));
  r->calibration_environment_mismatch_fraction = calibration.number("environment_mismatch_fraction", 0.01, 1);
  r->calibration_robot_link_fraction = calibration.number("robot_link_fraction", 0, 1);
  calibration.finish();
}

// risk.field: the protective field (after unknown_object_min_area_m2,
// which its intrusion distance is checked against).
void read_field(YamlMap field, RiskSettings* r) {
  r->field_approach_speed_m_s = field.number("approach_speed_m_s", 0.1, 10);
  r->field_chain_latency_us = field.milliseconds_as_us("chain_latency_ms", 0, 10000);
  r->field_stopping_time_us = field.milliseconds_as_us("stopping_time_ms", 0, 100000);
  r->field_stopping_distance_m = field.number("stopping_distance_m", 0, 10);
  r->field_intrusion_distance_m = field.number("intrusion_distance_m", 0, 10);
  r->field_warning_margin_m = field.number("warning_margin_m", 0, 10);
  // ISO 13855: an object smaller than the detection capability d can
  // reach through by C = 8 (d - 14 mm) before it is seen (0.85 m beyond
  // d = 40 mm); a smaller C would leave that reach unguarded.
  const double detection_capability_m = std::sqrt(r->unknown_object_min_area_m2);
  const double needed_m = iso13855_intrusion_distance_m(detection_capability_m);
  if (r->field_intrusion_distance_m < needed_m - 1e-9) {
    field.fail("intrusion_distance_m",
               "at least ISO 13855's C = " + std::to_string(needed_m) +
                   " m for the detection capability sqrt(unknown_object_min_area_m2) = " +
                   std::to_string(detection_capability_m * 1000) + " mm",
               std::to_string(r->field_intrusion_distance_m));
  }
  field.finish();
}

// risk.estimate: how the motion estimate confirms a diagnosis.
void read_estimate(YamlMap estimate, RiskSettings* r) {
  r->estimate_enabled = estimate.boolean("enabled");
  r->estimate_wait_us = estimate.milliseconds_as_us("wait_ms", 0, 1000);
  r->estimate_max_age_us = estimate.milliseconds_as_us("max_age_ms", 0, 10000);
  r->estimate_sigmas = estimate.number("sigmas", 0, 100);
  r->estimate_min_joint_offset_deg = estimate.number("min_joint_offset_deg", 0, 180);
  r->estimate_min_joint_offset_m = estimate.number("min_joint_offset_m", 0, 10);
  r->estimate_min_translation_m = estimate.number("min_translation_m", 0, 10);
  r->estimate_min_rotation_deg = estimate.number("min_rotation_deg", 0, 180);
  r->estimate_unexplained_residual_mm = estimate.number("unexplained_residual_mm", 0, 10000);
  estimate.finish();
}

// risk.evidence.large_joint_offset_{deg,m} (optional): the large-offset test's
// alternatives, each above the first test's (at or below it, the second
// test would repeat the first).
void read_large_joint_offset(YamlMap* evidence, RiskSettings* r) {
  const double deg =
      evidence->optional_number("large_joint_offset_deg", kDefaultLargeJointOffsetDeg, 0.01, 90);
  const double m = evidence->optional_number("large_joint_offset_m", kDefaultLargeJointOffsetM, 1e-5, 1);
  r->evidence_large_joint_offset_rad = deg * M_PI / 180.0;
  r->evidence_large_joint_offset_m = m;
  if (r->evidence_large_joint_offset_rad <= r->evidence_joint_offset_rad)
    evidence->fail("large_joint_offset_deg", "a number above joint_offset_deg", std::to_string(deg));
  if (m <= r->evidence_joint_offset_m)
    evidence->fail("large_joint_offset_m", "a number above joint_offset_m", std::to_string(m));
}

// risk.evidence: the sequential evidence tests.
void read_evidence(YamlMap evidence, RiskSettings* r) {
  r->evidence_false_stop_period_h = evidence.number("false_stop_period_h", 1e-3, 1e9);
  r->evidence_joint_offset_rad = evidence.number("joint_offset_deg", 0.01, 90) * M_PI / 180.0;
  r->evidence_joint_offset_m = evidence.number("joint_offset_m", 1e-5, 1);
  read_large_joint_offset(&evidence, r);
  r->evidence_camera_translation_m = evidence.number("camera_translation_m", 1e-4, 1);
  r->evidence_camera_rotation_rad = evidence.number("camera_rotation_deg", 0.01, 90) * M_PI / 180.0;
  r->evidence_warning_fraction = evidence.number("warning_fraction", 0.01, 1);
  r->evidence_clear_frames = static_cast<int>(evidence.integer("clear_frames", 1, 100000));
  evidence.finish();
}

// risk.plan: the planned trajectory check.
void read_plan(YamlMap plan, RiskSettings* r) {
  r->plan_enabled = plan.boolean("enabled");
  r->plan_max_deviation_deg = plan.number("max_deviation_deg", 0.01, 180);
  r->plan_max_deviation_m = plan.number("max_deviation_m", 1e-4, 10);
  plan.finish();
}

}  // namespace

RiskSettings read_risk_settings(YamlMap map) {
  RiskSettings r;
  r.check_period_us = map.milliseconds_as_us("check_period_ms", 1, 1000);
  r.debounce_frames = static_cast<int>(map.integer("debounce_frames", 1, 1000));
  r.sensor_debounce_frames = static_cast<int>(map.integer("sensor_debounce_frames", 1, 1000));
  read_deadlines(map.map("deadlines_ms"), &r);
  read_camera_pose(map.map("camera_pose"), &r);
  r.required_heartbeats = map.strings("required_heartbeats");
  r.continue_after_named_camera_release =
      map.choice("camera_loss", {"stop", "continue_after_named_reset"}) == "continue_after_named_reset";
  r.unseen_arm_max_fraction = map.number("unseen_arm_max_fraction", 0, 1);
  read_sensor(map.map("sensor"), &r);
  read_joint_error(map.map("joint_error"), &r);
  read_calibration_error(map.map("calibration_error"), &r);
  r.unknown_object_min_area_m2 = map.number("unknown_object_min_area_m2", 1e-6, 100);
  r.unclassified_blob_area_m2 = map.number("unclassified_blob_area_m2", 1e-6, 100);
  read_field(map.map("field"), &r);
  read_estimate(map.map("estimate"), &r);
  read_evidence(map.map("evidence"), &r);
  read_plan(map.map("plan"), &r);
  map.finish();
  return r;
}

double iso13855_intrusion_distance_m(double detection_capability_m) {
  if (detection_capability_m > 0.040) return 0.85;
  return std::max(0.0, 8.0 * (detection_capability_m - 0.014));
}

}  // namespace tofguard::settings
