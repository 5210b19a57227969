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
//  - two poses at most max_gap_us apart that differ are a motion (a pan-tilt
//    head's readings): between them the pose is interpolated (translation
//    linearly, rotation by slerp); beyond the newest of such a pair it is
//    extrapolated with the same motion at most max_extrapolation_us, and
//    before the oldest pose kept held for at most that long; further is
//    unusable (one line naming the camera, the gap and the limit);
//  - otherwise (one pose, equal poses, or poses further apart: a
//    calibration published now and then) a pose holds from its utime until
//    the next one, and the newest holds from then on, like the config's.
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

#include "tofguard/common/camera_settings.hpp"

namespace tofguard::robot_state {

struct PoseAtTime {
  bool usable = false;
  std::string unusable_reason;  // one line when !usable
  CameraPose pose;
};

class CameraPoseHistory {
 public:
  // Keeps poses no older than `history_us` behind each camera's newest (at
  // least two).
  CameraPoseHistory(int64_t history_us, int64_t max_extrapolation_us, int64_t max_gap_us);

  // The pose used for `camera_id` while no CAMERA_POSE has come for it.
  void set_static(const std::string& camera_id, const CameraPose& pose);

  // Adds a pose (finite, unit quaternion: check_camera_pose). Returns false
  // and ignores it when it is not newer than the camera's newest pose in the
  // same frame_id.
  bool add(const std::string& camera_id, int64_t utime, const CameraPose& pose);

  PoseAtTime at(const std::string& camera_id, int64_t utime) const;

  // True when the camera's two newest poses are a motion (they differ and
  // are at most max_gap_us apart).
  bool moving(const std::string& camera_id) const;

 private:
  struct Sample {
    int64_t utime;
    CameraPose pose;
  };
  struct Camera {
    std::deque<Sample> poses;
  };
  static CameraPose blend(const Sample& a, const Sample& b, int64_t utime);
  // True when a and b (a before b) are a motion.
  bool motion(const Sample& a, const Sample& b) const;

  int64_t history_us_;
  int64_t max_extrapolation_us_;
  int64_t max_gap_us_;
  std::map<std::string, CameraPose> static_poses_;
  std::map<std::string, Camera> cameras_;
};

}  // namespace tofguard::robot_state
