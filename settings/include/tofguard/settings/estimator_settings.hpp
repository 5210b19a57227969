#pragma once
// tofguard-estimator's settings (config section `estimator`,
// docs/estimator.md): when to estimate the joint offsets and the camera
// correction that best explain a camera frame. Durations are integer
// microseconds, converted once when the file is read.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "tofguard/common/camera_profile.hpp"
#include "tofguard/common/camera_settings.hpp"
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/robot_settings.hpp"
#include "tofguard/common/yaml_reader.hpp"
#include "tofguard/settings/occupant_settings.hpp"
#include "tofguard/settings/renderer_settings.hpp"

namespace tofguard::settings {

struct EstimatorSettings {
  // estimate_joints, estimate_camera: which parameters are estimated.
  bool estimate_joints = true;
  bool estimate_camera = true;
  // warning.{mismatch_fraction, p95_abs_dis_mm}: a frame is estimated at
  // once (TRIGGER_WARNING) when its discrepancy_t is usable and its
  // mismatch_fraction reaches warning_mismatch_fraction or its
  // p95_abs_dis_mm reaches warning_p95_abs_dis_mm.
  double warning_mismatch_fraction = 0;
  double warning_p95_abs_dis_mm = 0;
  // warning.min_interval_ms: at most one warning-triggered frame per this
  // much camera time (frame utimes): on a small CPU the estimator shares the
  // cores with the renderer, whose deadline stops the arm. Microseconds.
  int64_t warning_min_interval_us = 0;
  // periodic_period_ms: and the newest frame every this often
  // (TRIGGER_PERIODIC); microseconds.
  int64_t periodic_period_us = 0;
  // max_pending_frames: camera frames kept (by seq) until their discrepancy
  // arrives.
  int max_pending_frames = 0;
  // frames_per_estimate: frames estimated jointly
  // (MotionEstimator::estimate(frames)): the triggering frame and up to
  // frames_per_estimate - 1 kept frames just before it (at most
  // max_pending_frames in all).
  int frames_per_estimate = 0;
  // max_iterations, pixel_stride: Gauss-Newton iterations (one render each)
  // of the joints-and-camera stage, and every pixel_stride-th pixel's depth
  // residual.
  int max_iterations = 0;
  int pixel_stride = 0;
};

// Reads (and finishes) the `estimator` section.
EstimatorSettings read_estimator_settings(YamlMap section);

// Everything tofguard-estimator (and tofguard-calibrate-extrinsics) needs.
struct EstimatorProcessSettings {
  LcmSettings lcm;
  ChannelNames channels;
  RobotSettings robot;
  EnvironmentSettings environment;
  CameraSettings camera;
  // The renderer's clip distances and joint / camera-pose history windows:
  // the estimator renders and looks states up as tofguard-renderer does.
  renderer::RendererSettings renderer;
  // discrepancy.noise.{sigma_at_0m_mm, sigma_per_m2_mm}: the camera noise
  // model the estimator weighs residuals with, millimetres.
  double noise_sigma_at_0m_mm = 0;
  double noise_sigma_per_m2_mm = 0;
  // discrepancy.camera_profile (null: none): each frame is corrected by it
  // before the estimator compares it, as tofguard-discrepancy does; a frame
  // it does not fit is not estimated.
  std::shared_ptr<const CameraProfile> camera_profile;
  EstimatorSettings estimator;
  // The wheelchair's occupant (absent: none): rendered as tofguard-renderer
  // renders it, so that the user hides what is behind them and is not
  // taken for a camera or joint error.
  std::optional<OccupantSettings> occupant;
  // With several cameras, discrepancy.near_arm_m: a model pixel whose
  // measured depth is nearer by more than this takes no part
  // (EstimatorOptions::hidden_nearer_than_m); 0 with one camera.
  double hidden_nearer_than_m = 0;
  // With several cameras tofguard-risk publishes the worst camera's
  // verdict, its detail prefixed with that camera's id ("tof-side: "): only
  // a verdict of this camera's is about this camera's frame of that seq.
  bool several_cameras = false;
};

}  // namespace tofguard::settings

// The component's own names for its settings (tofguard::estimator::EstimatorSettings, ...).
namespace tofguard::estimator {
using settings::EstimatorProcessSettings;
using settings::EstimatorSettings;
using settings::read_estimator_settings;
}  // namespace tofguard::estimator
