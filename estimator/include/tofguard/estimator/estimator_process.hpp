#pragma once
// tofguard-estimator's wiring: the settings, LCM and the estimator library
// (which frames to estimate: EstimatorScheduler, estimator_scheduler.hpp),
// and the worker thread that estimates them without ever blocking the LCM
// loop (EstimatorWorker).
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/process.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/estimator/estimate_message.hpp"
#include "tofguard/estimator/estimator_scheduler.hpp"
#include "tofguard/estimator/estimator_settings.hpp"
#include "tofguard/estimator/motion_estimator.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tofguard/robot_state/state_history.hpp"

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

// Estimates jobs on its own thread (its own renderer and EGL context). One
// job waits at most: a newer one replaces it and counts as dropped.
class EstimatorWorker {
 public:
  EstimatorWorker(const robot_model::SceneModel& scene, const EstimatorProcessSettings& settings);
  ~EstimatorWorker();
  EstimatorWorker(const EstimatorWorker&) = delete;
  EstimatorWorker& operator=(const EstimatorWorker&) = delete;

  // Waits (up to 30 s) until the worker's renderer is up; "" or why not.
  std::string wait_ready();
  // Returns true when a waiting job was replaced (dropped).
  bool post(EstimateJob job);
  std::vector<motion_estimate_t> take_results();
  bool busy();

 private:
  void run();

  const robot_model::SceneModel& scene_;
  EstimatorProcessSettings settings_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool started_ = false;
  std::string start_error_;
  bool stop_ = false;
  bool working_ = false;
  std::optional<EstimateJob> pending_;
  std::vector<motion_estimate_t> results_;
  std::thread thread_;
};

}  // namespace tofguard::estimator
