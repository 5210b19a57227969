#pragma once
// The worker thread that estimates tofguard-estimator's jobs without ever
// blocking the LCM loop (EstimatorWorker).
#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "tofguard/estimator/estimator_scheduler.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tofguard/settings/estimator_settings.hpp"

namespace tofguard::estimator {

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
