#pragma once
// tofguard-estimator's wiring: the settings, LCM and the estimator library
// (which frames to estimate: EstimatorScheduler, estimator_scheduler.hpp;
// the worker thread that estimates them without ever blocking the LCM
// loop: EstimatorWorker, estimator_worker.hpp).
#include <optional>
#include <string>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/process.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/estimator/estimate_message.hpp"
#include "tofguard/estimator/estimator_scheduler.hpp"
#include "tofguard/estimator/estimator_worker.hpp"
#include "tofguard/estimator/motion_estimator.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tofguard/robot_state/state_history.hpp"
#include "tofguard/settings/estimator_settings.hpp"

namespace tofguard::estimator {

ProcessInfo process_info();

// The process: TOF_DEPTH, JOINT_STATE, CAMERA_POSE, SAFETY_DISCREPANCY, SAFETY_RISK in,
// MOTION_ESTIMATE out, until SIGINT/SIGTERM. Runs at niceness +10 (a
// diagnosis must not take time from the stop path). A scene that cannot be
// loaded is a configuration error (exit code 2).
int run_estimator(const EstimatorProcessSettings& settings);

// The estimator's options from the config (noise model from
// `discrepancy`, iterations and stride from `estimator`).
EstimatorOptions options_from_settings(const EstimatorProcessSettings& settings);

// The scene the estimator compares with the camera: the robot and the
// environment as the camera sees them (visual geometry, no padding).
robot_model::SceneModel load_estimator_scene(const EstimatorProcessSettings& settings);

}  // namespace tofguard::estimator
