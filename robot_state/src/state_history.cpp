#include "tofguard/robot_state/state_history.hpp"

#include "tofguard/common/camera_pose_message.hpp"

namespace tofguard::robot_state {

StateHistory::StateHistory(const StateHistorySettings& settings)
    : robot_id_(settings.robot_id),
      joints_(settings.joint_max_extrapolation_us, settings.joint_span_us, settings.joint_max_messages),
      camera_poses_(settings.camera_pose_history_us, settings.camera_pose_max_extrapolation_us,
                    settings.camera_pose_max_gap_us) {
  camera_poses_.set_static(settings.static_camera_id, settings.static_camera_pose);
}

bool StateHistory::add_joint_state(const joint_state_t& state) {
  if (state.robot_id != robot_id_) return false;
  robot_model::JointPositions positions;
  for (int i = 0; i < state.num_joints; ++i) positions[state.name[i]] = state.position[i];
  return joints_.add(state.utime, positions);
}

bool StateHistory::add_camera_pose(const camera_pose_t& pose) {
  return camera_poses_.add(pose.camera_id, pose.utime, from_camera_pose_message(pose));
}

StateAtFrame StateHistory::at(const std::string& camera_id, int64_t utime) const {
  return {joints_.at(utime), camera_poses_.at(camera_id, utime)};
}

}  // namespace tofguard::robot_state
