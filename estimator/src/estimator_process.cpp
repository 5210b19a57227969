#include "tofguard/estimator/estimator_process.hpp"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>

#include "tofguard/common/config_error.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/robot_model/kinematics.hpp"

namespace tofguard::estimator {

ProcessInfo process_info() {
  ProcessInfo info{
      "tofguard-estimator",
      "Estimates which joint offsets and which camera-pose correction best explain the camera's depth image "
      "(docs/estimator.md): TOF_DEPTH, JOINT_STATE, CAMERA_POSE, SAFETY_DISCREPANCY, SAFETY_RISK -> "
      "MOTION_ESTIMATE, for every frame whose discrepancy passes the warning level or that tofguard-risk "
      "judged a model mismatch, and periodically."};
  info.per_camera = true;
  return info;
}

EstimatorOptions options_from_settings(const EstimatorProcessSettings& settings) {
  EstimatorOptions o;
  o.estimate_joints = settings.estimator.estimate_joints;
  o.estimate_camera = settings.estimator.estimate_camera;
  o.noise.sigma_at_0m_mm = std::max(0.1, settings.noise_sigma_at_0m_mm);
  o.noise.sigma_per_m2_mm = settings.noise_sigma_per_m2_mm;
  o.max_iterations = settings.estimator.max_iterations;
  o.pixel_stride = settings.estimator.pixel_stride;
  o.hidden_nearer_than_m = settings.hidden_nearer_than_m;
  return o;
}

robot_model::SceneModel load_estimator_scene(const EstimatorProcessSettings& settings) {
  robot_model::SceneOptions options;
  options.geometry = robot_model::GeometrySource::kVisual;
  options.padding_m = 0;
  options.package_paths = settings.robot.package_paths;
  return robot_model::load_scene(settings.robot.urdf_path, settings.environment.urdf_paths, options);
}

namespace {

// Keeps the estimator out of the stop path's way: no llvmpipe render
// threads, and a lower priority.
void stay_out_of_the_stop_path(const std::string& name) {
  // The estimator renders 176x144-sized images a dozen times per frame on
  // its worker thread: llvmpipe's own render threads cost more in hand-over
  // than they save at that size (docs/benchmarks.md, motion estimator: 36 ms
  // per frame without them, 44 ms with). Set before the EGL display is
  // opened; a value in the environment wins.
  setenv("LP_NUM_THREADS", "0", /*overwrite=*/0);
  // The estimate is a diagnosis, not part of the stop path: on a small CPU
  // it must never take time from the renderer, discrepancy and risk, whose
  // deadlines stop the arm. Niceness +10 for the process and every thread
  // it starts (set before any thread exists).
  errno = 0;
  if (nice(10) == -1 && errno != 0) {
    std::cerr << name << ": cannot lower its priority (nice 10): " << std::strerror(errno) << "\n";
  }
}

// The LCM side: the inputs into the scheduler, its work to the worker (or
// out as unusable), the worker's estimates out, and the heartbeat.
class EstimatorWiring {
 public:
  EstimatorWiring(const EstimatorProcessSettings& settings, const std::string& name,
                  EstimatorScheduler* scheduler, EstimatorWorker* worker)
      : settings_(settings),
        node_(settings.lcm, settings.channels, name),
        scheduler_(*scheduler),
        worker_(*worker) {
    node_.heartbeat().set_status("waiting for frames");
  }

  void run() {
    subscribe_inputs();
    node_.add_timer(settings_.estimator.periodic_period_us, [this] {
      scheduler_.request_newest();
      dispatch();
    });
    node_.add_timer(5000, [this] { publish_results(); });
    node_.run();
  }

 private:
  void dispatch() {
    for (ScheduledWork& work : scheduler_.take_ready()) {
      if (work.unusable) {
        node_.safety().publish(settings_.channels.motion_estimate, &*work.unusable);
        node_.counters().frames_out++;
        ++unusable_;
        node_.errors().report("unusable", "frame " + std::to_string(work.unusable->seq) +
                                              " not estimated: " + work.unusable->unusable_reason);
      } else if (work.job && worker_.post(std::move(*work.job))) {
        // Behind: the waiting job was replaced by this newer one.
        node_.counters().frames_dropped++;
      }
    }
  }

  void subscribe_inputs() {
    const ChannelNames& channels = settings_.channels;
    node_.subscribe<joint_state_t>(
        node_.safety(), channels.joint_state,
        [this](const joint_state_t& state) {
          if (!scheduler_.on_joint_state(state)) {
            node_.counters().validation_errors++;
            node_.errors().report(settings_.channels.joint_state,
                                  settings_.channels.joint_state + ": ignored a message for robot_id '" +
                                      state.robot_id + "' (expected '" + settings_.robot.id +
                                      "') or not newer than the last");
          }
        },
        check_joint_state);
    node_.subscribe<camera_pose_t>(
        node_.safety(), channels.camera_pose,
        [this](const camera_pose_t& pose) { scheduler_.on_camera_pose(pose); }, check_camera_pose);
    node_.subscribe<depth_image_t>(
        node_.images(), channels.depth,
        [this](const depth_image_t& frame) {
          if (scheduler_.on_depth(frame)) {
            node_.heartbeat().set_last_frame_utime(frame.utime);
            dispatch();
          }
        },
        check_depth_image);
    node_.subscribe<discrepancy_t>(
        node_.safety(), channels.discrepancy,
        [this](const discrepancy_t& d) {
          scheduler_.on_discrepancy(d);
          dispatch();
        },
        check_discrepancy);
    node_.subscribe<risk_t>(
        node_.safety(), channels.risk,
        [this](const risk_t& r) {
          scheduler_.on_risk(r);
          dispatch();
        },
        check_risk);
  }

  void publish_results() {
    for (const motion_estimate_t& m : worker_.take_results()) {
      node_.safety().publish(settings_.channels.motion_estimate, &m);
      node_.counters().frames_out++;
      ++published_;
      if (!m.usable) ++unusable_;
    }
    node_.heartbeat().set_status(
        "estimates " + std::to_string(published_) + ", unusable " + std::to_string(unusable_) + ", missed " +
        std::to_string(scheduler_.missed()) + (worker_.busy() ? ", estimating" : ", idle"));
  }

  const EstimatorProcessSettings& settings_;
  LcmNode node_;
  EstimatorScheduler& scheduler_;
  EstimatorWorker& worker_;
  int64_t published_ = 0;
  int64_t unusable_ = 0;
};

}  // namespace

int run_estimator(const EstimatorProcessSettings& settings) {
  const std::string name = process_info().name;
  stay_out_of_the_stop_path(name);
  robot_model::SceneModel scene;
  try {
    scene = load_estimator_scene(settings);
  } catch (const std::exception& e) {
    std::cerr << name << ": " << e.what() << "\n";
    return kConfigErrorExitCode;
  }
  EstimatorWorker worker(scene, settings);
  const std::string worker_error = worker.wait_ready();
  if (!worker_error.empty()) {
    std::cerr << name << ": cannot start the estimator: " << worker_error << "\n";
    return 1;
  }
  EstimatorScheduler scheduler(settings, scene);
  EstimatorWiring(settings, name, &scheduler, &worker).run();
  return 0;
}

}  // namespace tofguard::estimator
