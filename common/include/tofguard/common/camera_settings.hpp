#pragma once
// The camera every process agrees on (config section `camera`: id, rate_hz,
// intrinsics, pose): the renderer renders from it, the discrepancy and risk
// processes check frames come from it, the camera publishes it. The camera
// drivers' own settings (camera.uvc, camera.depth_calibration) live in
// camera/ and the simulated camera's (camera.sim) in sim/.
#include <string>

#include <Eigen/Geometry>

#include "tofguard/common/yaml_reader.hpp"

namespace tofguard {

// Pinhole intrinsics, OpenCV convention (pixel (u, v) has its centre at
// (u, v), u right, v down), in pixels.
struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0;
  double fy = 0;
  double cx = 0;
  double cy = 0;
};

// Pose of the camera's optical frame (x right, y down, z forward) in URDF
// link `frame_id`: p_frame = rotation * p_optical + translation_m.
struct CameraPose {
  std::string frame_id;
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();

  // The optical frame's pose in frame_id as a transform:
  // p_frame = frame_from_optical() * p_optical (rotation normalised).
  Eigen::Isometry3d frame_from_optical() const {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = rotation.normalized().toRotationMatrix();
    t.translation() = translation_m;
    return t;
  }
};

struct CameraSettings {
  // camera.id: depth_image_t.camera_id of the camera watched.
  std::string id;
  // camera.rate_hz: frames per second.
  double rate_hz = 0;
  // camera.intrinsics (width, height, fx, fy, cx, cy).
  Intrinsics intrinsics;
  // camera.pose (frame, translation_m, rotation_wxyz): the static
  // calibrated pose, used until a CAMERA_POSE message arrives.
  CameraPose pose;
};

// camera.intrinsics; the caller finishes the mapping.
Intrinsics read_intrinsics(YamlMap& section);
// camera.pose: the rotation must be a unit quaternion (within 1e-6).
CameraPose read_camera_pose(YamlMap section);

}  // namespace tofguard
