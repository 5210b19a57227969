#pragma once
// The robot's state at a camera frame's utime: the joints (JOINT_STATE
// interpolated, JointHistory) and the camera pose (CAMERA_POSE per
// camera_id, else the config's static pose, CameraPoseHistory), as the
// renderer, the estimator and the extrinsics calibration look them up.
// The histories' limits come from the renderer's settings (durations already
// in microseconds; renderer::state_history_settings builds them), so that
// every process that renders or compares the model judges a frame by the
// same limits.
//
// Times are utime (microseconds since the Unix epoch, as on the wire).
#include <cstddef>
#include <cstdint>
#include <string>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/robot_model/kinematics.hpp"
#include "tofguard/robot_state/camera_pose_history.hpp"
#include "tofguard/robot_state/joint_history.hpp"

namespace tofguard::robot_state {

struct StateHistorySettings {
  // joint_state_t messages of other robots are ignored.
  std::string robot_id;
  // JointHistory: how far a frame may lie beyond the newest joint state,
  // how long and how many messages are kept.
  int64_t joint_max_extrapolation_us = 0;
  int64_t joint_span_us = 2'000'000;
  size_t joint_max_messages = 1000;
  // CameraPoseHistory (docs/renderer.md, "Camera pose history").
  int64_t camera_pose_history_us = 0;
  int64_t camera_pose_max_extrapolation_us = 0;
  int64_t camera_pose_max_gap_us = 0;
  // The pose used for static_camera_id while no CAMERA_POSE has come for it.
  std::string static_camera_id;
  CameraPose static_camera_pose;
};

// The state at one frame's utime. Joints and camera pose are looked up
// apart: a caller may use the one that is usable when the other is not
// (e.g. to describe the frame).
struct StateAtFrame {
  JointsAtTime joints;
  PoseAtTime camera_pose;

  bool usable() const { return joints.usable && camera_pose.usable; }
  // One line when !usable(): the joints' reason first, else the pose's.
  const std::string& unusable_reason() const {
    return !joints.usable ? joints.unusable_reason : camera_pose.unusable_reason;
  }
};

class StateHistory {
 public:
  explicit StateHistory(const StateHistorySettings& settings);

  // Adds a joint state (one that passed check_joint_state). Returns false
  // and ignores it for another robot's state or one not newer than the
  // newest (the caller counts that).
  bool add_joint_state(const joint_state_t& state);
  // Adds a pose (one that passed check_camera_pose). Returns false and
  // ignores it when it is not newer than the camera's newest in the same
  // frame_id.
  bool add_camera_pose(const camera_pose_t& pose);

  // The state of camera `camera_id`'s frame captured at `utime`.
  StateAtFrame at(const std::string& camera_id, int64_t utime) const;

  const JointHistory& joints() const { return joints_; }
  const CameraPoseHistory& camera_poses() const { return camera_poses_; }

 private:
  std::string robot_id_;
  JointHistory joints_;
  CameraPoseHistory camera_poses_;
};

}  // namespace tofguard::robot_state
