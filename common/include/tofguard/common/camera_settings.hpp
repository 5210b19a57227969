#pragma once
// The camera every process agrees on (config section `camera`: id, rate_hz,
// intrinsics, pose): the renderer renders from it, the discrepancy and risk
// processes check frames come from it, the camera publishes it. The camera
// drivers' own settings (camera.uvc, camera.depth_calibration) live in
// camera/ and the simulated camera's (camera.sim) in sim/.
#include <string>

#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/common/yaml_reader.hpp"

namespace tofguard {

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

// camera.intrinsics, checked by Intrinsics::check (camera_geometry.hpp); the
// caller finishes the mapping.
Intrinsics read_intrinsics(YamlMap& section);
// camera.pose: the rotation must be a unit quaternion (within
// kConfigQuaternionTolerance).
CameraPose read_camera_pose(YamlMap section);

}  // namespace tofguard
