#pragma once
// Validation of decoded wire messages. Each check returns "" for a valid
// message, else one line naming the field and what was expected, e.g.
//   "num_pixels: expected width*height = 25344, got 100"
// A message that fails its check is dropped and counted, never used.
#include <string>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"

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
// level and cause must be one of risk_t's constants.
std::string check_risk(const risk_t& risk);
// stop and cause must be one of the constants.
std::string check_safety_status(const safety_status_t& status);
// utime > 0, seq >= 0, a camera_id, trigger one of the constants; an
// unusable estimate needs its reason and nothing else. A usable one: unique
// non-empty joint names, finite positions, sigmas >= 0 and finite, unit
// quaternions (within 1e-3) for the correction and the estimated pose, a
// frame_id, 0 <= num_inliers <= num_points, finite residuals >= 0.
std::string check_motion_estimate(const motion_estimate_t& estimate);
// At least one joint (unique non-empty names) and one point; point utimes
// > 0 and strictly increasing; finite positions.
std::string check_planned_trajectory(const planned_trajectory_t& plan);

}  // namespace tofguard
