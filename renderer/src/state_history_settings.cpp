#include "tofguard/renderer/state_history_settings.hpp"

namespace tofguard::renderer {

robot_state::StateHistorySettings state_history_settings(const RendererSettings& renderer,
                                                         const std::string& robot_id,
                                                         const CameraSettings& camera) {
  robot_state::StateHistorySettings s;
  s.robot_id = robot_id;
  s.joint_max_extrapolation_us = renderer.max_extrapolation_us;
  s.camera_pose_history_us = renderer.camera_pose_history_us;
  s.camera_pose_max_extrapolation_us = renderer.camera_pose_max_extrapolation_us;
  s.camera_pose_max_gap_us = renderer.camera_pose_max_gap_us;
  s.static_camera_id = camera.id;
  s.static_camera_pose = camera.pose;
  return s;
}

}  // namespace tofguard::renderer
