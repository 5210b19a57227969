#pragma once
// CameraPose (camera_settings.hpp) to and from the wire's camera_pose_t: the same
// convention (the optical frame's pose in frame_id, p_frame = R * p_optical
// + t, quaternion w, x, y, z).
#include <cstdint>
#include <string>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/camera_geometry.hpp"

namespace tofguard {

camera_pose_t to_camera_pose_message(const std::string& camera_id, int64_t utime, const CameraPose& pose);
// `message` must have passed check_camera_pose (TOFGUARD_DEMANDed); the
// rotation is normalised (the check allows a norm within 1e-3 of 1).
CameraPose from_camera_pose_message(const camera_pose_t& message);

}  // namespace tofguard
