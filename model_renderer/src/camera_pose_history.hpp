#pragma once
// The camera poses tofguard-renderer renders from: per camera_id, a short
// history of CAMERA_POSE messages (a pan-tilt head, a calibration tool),
// looked up at each frame's utime, so that a moving camera is followed at
// run time without restart and each frame is rendered from where the
// camera was when it was captured.
//
// Lookup rules (docs/renderer.md, "Camera pose history"):
//  - no CAMERA_POSE for the camera yet: its static pose (the config's
//    camera.pose for camera.id), else unusable;
//  - every pose received for the camera so far is the same (a calibration
//    published once or repeated): that pose, at any time, like the config's;
//  - once the camera's pose has changed, it is "moving": between two poses
//    the pose is interpolated (translation linearly, rotation by slerp);
//    beyond the newest pose it is extrapolated linearly from the last two,
//    at most max_extrapolation_us; before the oldest pose kept, that pose is
//    held for at most max_extrapolation_us; further is unusable (one line
//    naming the camera, the gap and the limit).
// A pose in another frame_id than the camera's previous ones starts the
// camera's history anew (interpolating across frames means nothing).
//
// Poses are tofguard::CameraPose: the optical frame's pose in link
// frame_id, p_frame = rotation * p_optical + translation_m. Times are
// utime (microseconds since the Unix epoch).
#include <cstdint>
#include <deque>
#include <map>
#include <string>

#include "tofguard/config.hpp"

namespace tofguard::renderer {

struct PoseAtTime {
  bool usable = false;
  std::string unusable_reason;  // one line when !usable
  CameraPose pose;
};

class CameraPoseHistory {
 public:
  // Keeps poses no older than `history_us` behind each camera's newest (at
  // least two).
  CameraPoseHistory(int64_t history_us, int64_t max_extrapolation_us);

  // The pose used for `camera_id` while no CAMERA_POSE has come for it.
  void set_static(const std::string& camera_id, const CameraPose& pose);

  // Adds a pose (finite, unit quaternion: check_camera_pose). Returns false
  // and ignores it when it is not newer than the camera's newest pose in the
  // same frame_id.
  bool add(const std::string& camera_id, int64_t utime, const CameraPose& pose);

  PoseAtTime at(const std::string& camera_id, int64_t utime) const;

  // True once the camera's reported pose has changed.
  bool moving(const std::string& camera_id) const;

 private:
  struct Sample {
    int64_t utime;
    CameraPose pose;
  };
  struct Camera {
    std::deque<Sample> poses;
    bool moving = false;
  };
  static CameraPose blend(const Sample& a, const Sample& b, int64_t utime);

  int64_t history_us_;
  int64_t max_extrapolation_us_;
  std::map<std::string, CameraPose> static_poses_;
  std::map<std::string, Camera> cameras_;
};

}  // namespace tofguard::renderer
