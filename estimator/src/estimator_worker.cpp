#include "tofguard/estimator/estimator_worker.hpp"

#include <chrono>
#include <memory>
#include <utility>

#include "tofguard/estimator/estimator_process.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/rendered_occupant.hpp"
#include "tofguard/robot_model/occupant_model.hpp"

namespace tofguard::estimator {

EstimatorWorker::EstimatorWorker(const robot_model::SceneModel& scene,
                                 const EstimatorProcessSettings& settings)
    : scene_(scene), settings_(settings), thread_([this] { run(); }) {}

EstimatorWorker::~EstimatorWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

std::string EstimatorWorker::wait_ready() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!wake_.wait_for(lock, std::chrono::seconds(30), [&] { return started_; })) {
    return "the estimator's renderer did not start within 30 s";
  }
  return start_error_;
}

bool EstimatorWorker::post(EstimateJob job) {
  bool dropped;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    dropped = pending_.has_value();
    pending_ = std::move(job);
  }
  wake_.notify_all();
  return dropped;
}

std::vector<motion_estimate_t> EstimatorWorker::take_results() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<motion_estimate_t> out;
  out.swap(results_);
  return out;
}

bool EstimatorWorker::busy() {
  std::lock_guard<std::mutex> lock(mutex_);
  return working_ || pending_.has_value();
}

void EstimatorWorker::run() {
  std::unique_ptr<renderer::DepthRenderer> renderer;
  std::unique_ptr<MotionEstimator> estimator;
  try {
    // The renderer's GL context belongs to this thread.
    renderer = std::make_unique<renderer::DepthRenderer>(scene_, settings_.renderer.near_m,
                                                         settings_.renderer.far_m);
    std::vector<renderer::ExtraObject> occupant;
    if (settings_.occupant) {
      occupant = renderer::occupant_render_objects(
          robot_model::load_occupant(settings_.occupant->urdf_path,
                                     robot_model::fixed_link_pose(scene_, settings_.occupant->seated_on)));
    }
    estimator = std::make_unique<MotionEstimator>(scene_, renderer.get(), options_from_settings(settings_),
                                                  std::move(occupant));
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    start_error_ = e.what();
    started_ = true;
    wake_.notify_all();
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    started_ = true;
  }
  wake_.notify_all();
  while (true) {
    EstimateJob job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || pending_.has_value(); });
      if (stop_) return;
      job = std::move(*pending_);
      pending_.reset();
      working_ = true;
    }
    const EstimateResult result = estimator->estimate(job.frames);
    motion_estimate_t message = to_message(result, job.context);
    std::lock_guard<std::mutex> lock(mutex_);
    results_.push_back(std::move(message));
    working_ = false;
  }
}

}  // namespace tofguard::estimator
