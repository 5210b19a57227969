#include "tofguard/common/camera_pose_message.hpp"

namespace tofguard {

camera_pose_t to_camera_pose_message(const std::string& camera_id, int64_t utime, const CameraPose& pose) {
  camera_pose_t m;
  m.utime = utime;
  m.camera_id = camera_id;
  m.frame_id = pose.frame_id;
  for (int i = 0; i < 3; ++i) m.translation[i] = pose.translation_m[i];
  m.rotation[0] = pose.rotation.w();
  m.rotation[1] = pose.rotation.x();
  m.rotation[2] = pose.rotation.y();
  m.rotation[3] = pose.rotation.z();
  return m;
}

CameraPose from_camera_pose_message(const camera_pose_t& m) {
  // The message passed check_camera_pose (a checked subscription); the
  // constructors DEMAND what it checked.
  return CameraPose(
      m.frame_id, Eigen::Vector3d(m.translation[0], m.translation[1], m.translation[2]),
      UnitQuaternion(Eigen::Quaterniond(m.rotation[0], m.rotation[1], m.rotation[2], m.rotation[3]),
                     kWireQuaternionTolerance));
}

}  // namespace tofguard
