#pragma once
// Validation of decoded wire messages. Each check returns "" for a valid
// message, else one line naming the field and what was expected, e.g.
//   "num_pixels: expected width*height = 25344, got 100"
// A message that fails its check is dropped and counted, never used.
#include <string>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/sim_camera_fault_t.hpp"
#include "tofguard/sim_controller_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"
#include "tofguard/speed_limit_t.hpp"

namespace tofguard {

// The intrinsics by Intrinsics::check (camera_geometry.hpp).
std::string check_depth_image(const depth_image_t& image);
// check_depth_image, and the frame must come from camera `camera_id`.
std::string check_depth_image_from(const depth_image_t& image, const std::string& camera_id);
std::string check_joint_state(const joint_state_t& state);
// CameraPose::check with kWireQuaternionTolerance (a unit quaternion within
// 1e-3, normalised by from_camera_pose_message).
std::string check_camera_pose(const camera_pose_t& pose);
std::string check_link_labels(const link_labels_t& labels);
// link_labels_t's arm cover alone (arm_cover_max_radius_m ..
// arm_sphere_radius_m: counts, links in range, finite centres, radii up to
// the maximum); part of check_link_labels, and what compute_discrepancy
// checks itself before it reads the cover.
std::string check_arm_cover(const link_labels_t& labels);
// level and cause must be one of risk_t's constants.
std::string check_risk(const risk_t& risk);
// stop and cause must be one of the constants.
std::string check_safety_status(const safety_status_t& status);
// max_arm_speed_m_s finite >= 0, set_by one of the constants, arm_speed_m_s
// finite >= 0 or -1 (not bounded), valid_for_ms > 0.
std::string check_speed_limit(const speed_limit_t& limit);
// utime > 0, seq >= 0, a camera_id, trigger one of the constants; an
// unusable estimate needs its reason and nothing else. A usable one: unique
// non-empty joint names, finite positions, sigmas >= 0 and finite, unit
// quaternions (within 1e-3) for the correction and the estimated pose, a
// frame_id, 0 <= num_inliers <= num_points, finite residuals >= 0.
std::string check_motion_estimate(const motion_estimate_t& estimate);
// At least one joint (unique non-empty names) and one point; point utimes
// > 0 and strictly increasing; finite positions.
std::string check_planned_trajectory(const planned_trajectory_t& plan);
// The summary's own consistency (the decoder already sized the arrays):
// utime > 0, seq >= 0, 0 <= num_robot_links <= num_links, invalid_fraction
// and mismatch_fraction in [0, 1], p95_abs_dis_mm finite and >= 0, per link
// 0 <= match, farther <= compared, finite near-arm and blob areas.
std::string check_discrepancy(const discrepancy_t& discrepancy);
// A process name.
std::string check_heartbeat(const heartbeat_t& heartbeat);
// kind one of the constants; for a fault (not CLEAR) a duration in
// (0, 1e6) s; finite vectors; an intruding object's sizes > 0.
std::string check_sim_camera_fault(const sim_camera_fault_t& fault);
// A joint name and a finite offset (rad, or m for a prismatic joint).
std::string check_sim_joint_fault(const sim_joint_fault_t& fault);
// utime > 0; a finite drive_rad_s, 0 without a drive_joint.
std::string check_sim_controller_fault(const sim_controller_fault_t& fault);

}  // namespace tofguard
