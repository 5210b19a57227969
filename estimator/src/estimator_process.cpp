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
  return {
      "tofguard-estimator",
      "Estimates which joint offsets and which camera-pose correction best explain the camera's depth image "
      "(docs/estimator.md): TOF_DEPTH, JOINT_STATE, CAMERA_POSE, SAFETY_DISCREPANCY, SAFETY_RISK -> "
      "MOTION_ESTIMATE, for every frame whose discrepancy passes the warning level or that tofguard-risk "
      "judged a model mismatch, and periodically."};
}

EstimatorOptions options_from_settings(const EstimatorProcessSettings& settings) {
  EstimatorOptions o;
  o.estimate_joints = settings.estimator.estimate_joints;
  o.estimate_camera = settings.estimator.estimate_camera;
  o.noise_sigma_at_0m_m = std::max(1e-4, settings.noise_sigma_at_0m_mm / 1000.0);
  o.noise_sigma_per_m2_m = settings.noise_sigma_per_m2_mm / 1000.0;
  o.max_iterations = settings.estimator.max_iterations;
  o.pixel_stride = settings.estimator.pixel_stride;
  return o;
}

robot_model::SceneModel load_estimator_scene(const EstimatorProcessSettings& settings) {
  robot_model::SceneOptions options;
  options.geometry = robot_model::GeometrySource::kVisual;
  options.padding_m = 0;
  options.package_paths = settings.robot.package_paths;
  return robot_model::load_scene(settings.robot.urdf_path, settings.environment.urdf_paths, options);
}

int run_estimator(const EstimatorProcessSettings& settings) {
  const std::string name = process_info().name;
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
  LcmNode node(settings.lcm, settings.channels, name);
  node.heartbeat().set_status("waiting for frames");
  int64_t published = 0;
  int64_t unusable = 0;

  auto dispatch = [&] {
    for (ScheduledWork& work : scheduler.take_ready()) {
      if (work.unusable) {
        node.safety().publish(settings.channels.motion_estimate, &*work.unusable);
        node.counters().frames_out++;
        ++unusable;
        node.errors().report("unusable", "frame " + std::to_string(work.unusable->seq) +
                                             " not estimated: " + work.unusable->unusable_reason);
      } else if (work.job && worker.post(std::move(*work.job))) {
        // Behind: the waiting job was replaced by this newer one.
        node.counters().frames_dropped++;
      }
    }
  };

  node.subscribe<joint_state_t>(
      node.safety(), settings.channels.joint_state,
      [&](const joint_state_t& state) {
        if (!scheduler.on_joint_state(state)) {
          node.counters().validation_errors++;
          node.errors().report(settings.channels.joint_state,
                               settings.channels.joint_state + ": ignored a message for robot_id '" +
                                   state.robot_id + "' (expected '" + settings.robot.id +
                                   "') or not newer than the last");
        }
      },
      check_joint_state);
  node.subscribe<camera_pose_t>(
      node.safety(), settings.channels.camera_pose,
      [&](const camera_pose_t& pose) { scheduler.on_camera_pose(pose); }, check_camera_pose);
  node.subscribe<depth_image_t>(
      node.images(), settings.channels.depth,
      [&](const depth_image_t& frame) {
        if (scheduler.on_depth(frame)) {
          node.heartbeat().set_last_frame_utime(frame.utime);
          dispatch();
        }
      },
      check_depth_image);
  node.subscribe<discrepancy_t>(
      node.safety(), settings.channels.discrepancy,
      [&](const discrepancy_t& d) {
        scheduler.on_discrepancy(d);
        dispatch();
      },
      check_discrepancy);
  node.subscribe<risk_t>(
      node.safety(), settings.channels.risk,
      [&](const risk_t& r) {
        scheduler.on_risk(r);
        dispatch();
      },
      check_risk);
  node.add_timer(settings.estimator.periodic_period_us, [&] {
    scheduler.request_newest();
    dispatch();
  });
  node.add_timer(5000, [&] {
    for (const motion_estimate_t& m : worker.take_results()) {
      node.safety().publish(settings.channels.motion_estimate, &m);
      node.counters().frames_out++;
      ++published;
      if (!m.usable) ++unusable;
    }
    node.heartbeat().set_status("estimates " + std::to_string(published) + ", unusable " +
                                std::to_string(unusable) + ", missed " + std::to_string(scheduler.missed()) +
                                (worker.busy() ? ", estimating" : ", idle"));
  });
  node.run();
  return 0;
}

}  // namespace tofguard::estimator
