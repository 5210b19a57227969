#pragma once
// Validation of decoded wire messages. Each check returns "" for a valid
// message, else one line naming the field and what was expected, e.g.
//   "num_pixels: expected width*height = 25344, got 100"
// A message that fails its check is dropped and counted, never used.
#include <string>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"

namespace tofguard {

// Largest image side accepted, pixels.
constexpr int kMaxImageSide = 8192;

std::string check_depth_image(const depth_image_t& image);
// check_depth_image, and the frame must come from camera `camera_id`.
std::string check_depth_image_from(const depth_image_t& image, const std::string& camera_id);
std::string check_joint_state(const joint_state_t& state);
// The rotation must be a unit quaternion within 1e-3.
std::string check_camera_pose(const camera_pose_t& pose);
std::string check_link_labels(const link_labels_t& labels);
// level and cause must be one of risk_t's constants.
std::string check_risk(const risk_t& risk);
// stop and cause must be one of the constants.
std::string check_safety_status(const safety_status_t& status);

}  // namespace tofguard
