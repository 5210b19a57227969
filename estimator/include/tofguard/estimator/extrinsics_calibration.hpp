#pragma once
// tofguard-calibrate-extrinsics: the camera's pose from an
// LCM log of the arm moving with known joint angles. The motion estimator
// with the joints fixed (they are exact) and the camera free, jointly over
// several frames of diverse arm poses.
#include <string>
#include <vector>

#include "tofguard/estimator/motion_estimator.hpp"
#include "tofguard/settings/estimator_settings.hpp"

namespace tofguard::estimator {

struct CalibrationOptions {
  // At most this many frames, chosen greedily for diverse joint positions
  // (each next frame the farthest, in the largest joint difference, from
  // those chosen), each at least min_pose_distance_rad from the others.
  int max_frames = 6;
  int min_frames = 3;
  double min_pose_distance_rad = 0.05;
  int max_iterations = 40;
  // The estimator's robust scale schedule (EstimatorOptions).
  double initial_robust_scale_m = 0.8;
  double robust_scale_factor = 0.9;
};

struct CalibrationResult {
  // "" on success; else one line (missing channel, too few frames, did not
  // converge).
  std::string error;
  int frames_in_log = 0;
  int frames_used = 0;
  int iterations = 0;
  // The camera's optical frame in the config pose's frame_id.
  CameraPose pose;
  double translation_sigma_m = 0;
  double rotation_sigma_rad = 0;
  double residual_before_mm = 0;
  double residual_after_mm = 0;
};

// Reads `log_path` (TOF_DEPTH of the config's camera, JOINT_STATE of its
// robot; channel names from the settings) and estimates the camera pose,
// starting from the config's camera.pose.
CalibrationResult calibrate_extrinsics(const EstimatorProcessSettings& settings, const std::string& log_path,
                                       const CalibrationOptions& options);

// The pose as the config's camera.pose YAML block.
std::string pose_yaml(const CameraPose& pose);

}  // namespace tofguard::estimator
