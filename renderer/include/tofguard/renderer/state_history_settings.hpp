#pragma once
#include <string>

#include "tofguard/common/camera_settings.hpp"
#include "tofguard/robot_state/state_history.hpp"
#include "tofguard/settings/renderer_settings.hpp"

namespace tofguard::renderer {

// The state history's limits (the renderer's max_extrapolation_us and
// camera_pose_*_us, as read), the robot's id and the camera's id and static
// pose: every process that renders or compares the model (renderer,
// estimator, extrinsics calibration) builds its StateHistory from this.
robot_state::StateHistorySettings state_history_settings(const RendererSettings& renderer,
                                                         const std::string& robot_id,
                                                         const CameraSettings& camera);

}  // namespace tofguard::renderer
