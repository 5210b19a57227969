#include "tofguard/estimator/extrinsics_calibration.hpp"

#include <lcm/lcm-cpp.hpp>

#include <cmath>
#include <iomanip>
#include <limits>
#include <memory>
#include <sstream>

#include "tofguard/common/decode.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/estimator/estimator_process.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/state_history_settings.hpp"
#include "tofguard/robot_state/state_history.hpp"

namespace tofguard::estimator {

namespace {

double pose_distance(const robot_model::JointPositions& a, const robot_model::JointPositions& b) {
  double d = 0;
  for (const auto& [name, value] : a) {
    const auto other = b.find(name);
    if (other != b.end()) d = std::max(d, std::abs(value - other->second));
  }
  return d;
}

// The state history of a whole log: every joint state is kept (the frames
// need the states around them).
robot_state::StateHistorySettings whole_log_history(const EstimatorProcessSettings& settings) {
  robot_state::StateHistorySettings state_settings =
      renderer::state_history_settings(settings.renderer, settings.robot.id, settings.camera);
  state_settings.joint_span_us = std::numeric_limits<int64_t>::max() / 4;
  state_settings.joint_max_messages = std::numeric_limits<size_t>::max();
  return state_settings;
}

// The log's joint states (into *history, counted in *joint_states) and the
// camera's depth frames. The camera pose is the settings' (CAMERA_POSE is
// not read: the pose is what is being calibrated).
std::vector<depth_image_t> read_log(const EstimatorProcessSettings& settings, lcm::LogFile* log,
                                    robot_state::StateHistory* history, int* joint_states) {
  std::vector<depth_image_t> frames;
  for (const lcm::LogEvent* event = log->readNextEvent(); event != nullptr; event = log->readNextEvent()) {
    if (event->channel == settings.channels.joint_state) {
      const auto state = decode_message<joint_state_t>(event->data, event->datalen);
      if (!state || !check_joint_state(*state).empty()) continue;
      if (history->add_joint_state(*state)) ++*joint_states;
    } else if (event->channel == settings.channels.depth) {
      const auto frame = decode_message<depth_image_t>(event->data, event->datalen);
      if (!frame || !check_depth_image_from(*frame, settings.camera.id).empty()) continue;
      frames.push_back(*frame);
    }
  }
  return frames;
}

// Why the camera cannot be calibrated on this scene (its frame is not a
// link, or moves with a joint); empty when it can.
std::string camera_frame_error(const robot_model::SceneModel& scene,
                               const EstimatorProcessSettings& settings) {
  if (scene.find_link(settings.camera.pose.frame_id) < 0) {
    return "camera.pose.frame '" + settings.camera.pose.frame_id + "' is not a model link";
  }
  const std::string moving = scene.nearest_movable_joint_above(settings.camera.pose.frame_id);
  if (!moving.empty()) {
    return "camera.pose.frame '" + settings.camera.pose.frame_id + "' moves with joint '" + moving +
           "': only a static camera can be calibrated";
  }
  return "";
}

// A frame with joint states around it.
struct Candidate {
  const depth_image_t* frame;
  robot_model::JointPositions joints;
};

std::vector<Candidate> candidates_of(const std::vector<depth_image_t>& frames,
                                     const robot_state::StateHistory& history) {
  std::vector<Candidate> candidates;
  for (const depth_image_t& frame : frames) {
    const robot_state::StateAtFrame state = history.at(frame.camera_id, frame.utime);
    if (state.joints.usable) candidates.push_back({&frame, state.joints.joints});
  }
  return candidates;
}

// The most diverse poses: the first candidate, then each time the one
// farthest (at least min_pose_distance_rad) from those chosen.
std::vector<const Candidate*> most_diverse(const std::vector<Candidate>& candidates,
                                           const CalibrationOptions& options) {
  std::vector<const Candidate*> chosen;
  if (!candidates.empty()) chosen.push_back(&candidates.front());
  while (static_cast<int>(chosen.size()) < options.max_frames) {
    const Candidate* best = nullptr;
    double best_distance = options.min_pose_distance_rad;
    for (const Candidate& c : candidates) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const Candidate* o : chosen) nearest = std::min(nearest, pose_distance(c.joints, o->joints));
      if (nearest >= best_distance) {
        best_distance = nearest;
        best = &c;
      }
    }
    if (best == nullptr) break;
    chosen.push_back(best);
  }
  return chosen;
}

std::vector<EstimatorFrame> estimator_frames_of(const std::vector<const Candidate*>& chosen,
                                                const Eigen::Isometry3d& world_from_optical) {
  std::vector<EstimatorFrame> estimator_frames;
  for (const Candidate* c : chosen) {
    EstimatorFrame f;
    const depth_image_t& d = *c->frame;
    f.intrinsics = intrinsics_of(d);
    f.reported_joints = c->joints;
    f.world_from_optical = world_from_optical;
    f.depth_m = depth_m_of(d);
    estimator_frames.push_back(std::move(f));
  }
  return estimator_frames;
}

// The camera alone, from the settings' pose.
EstimatorOptions calibration_estimator_options(const EstimatorProcessSettings& settings,
                                               const CalibrationOptions& options) {
  EstimatorOptions estimator_options = options_from_settings(settings);
  estimator_options.estimate_joints = false;
  estimator_options.estimate_camera = true;
  estimator_options.max_iterations = options.max_iterations;
  // A 5 cm / 5 degree start is 15-20 pixels off: start coarser and shrink
  // more slowly than for a frame-to-frame estimate.
  estimator_options.initial_robust_scale_m = options.initial_robust_scale_m;
  estimator_options.robust_scale_factor = options.robust_scale_factor;
  return estimator_options;
}

// The estimate's residuals, sigmas and pose (in the settings' frame) into
// *result; an error when it did not converge.
void store_estimate(const EstimateResult& estimate, const Eigen::Isometry3d& frame_from_optical,
                    const EstimatorProcessSettings& settings, CalibrationResult* result) {
  result->iterations = estimate.iterations;
  result->residual_before_mm = estimate.residual_before_m * 1000;
  result->residual_after_mm = estimate.residual_after_m * 1000;
  result->translation_sigma_m = estimate.correction_translation_sigma_m;
  result->rotation_sigma_rad = estimate.correction_rotation_sigma_rad;
  const Eigen::Isometry3d estimated = frame_from_optical * estimate.correction;
  result->pose.frame_id = settings.camera.pose.frame_id;
  result->pose.translation_m = estimated.translation();
  result->pose.rotation = Eigen::Quaterniond(estimated.linear());
  if (!estimate.converged) {
    result->error = "did not converge in " + std::to_string(estimate.iterations) + " iterations (residual " +
                    std::to_string(result->residual_before_mm) + " -> " +
                    std::to_string(result->residual_after_mm) +
                    " mm): is the initial pose within ~5 cm / 5 deg?";
  }
}

}  // namespace

std::string pose_yaml(const CameraPose& pose) {
  const Eigen::Quaterniond q = pose.rotation.normalized();
  std::ostringstream out;
  out << std::setprecision(9);
  out << "pose:\n"
      << "  frame: " << pose.frame_id << "\n"
      << "  translation_m: [" << pose.translation_m.x() << ", " << pose.translation_m.y() << ", "
      << pose.translation_m.z() << "]\n"
      << "  rotation_wxyz: [" << q.w() << ", " << q.x() << ", " << q.y() << ", " << q.z() << "]\n";
  return out.str();
}

CalibrationResult calibrate_extrinsics(const EstimatorProcessSettings& settings, const std::string& log_path,
                                       const CalibrationOptions& options) {
  CalibrationResult result;
  lcm::LogFile log(log_path, "r");
  if (!log.good()) {
    result.error = log_path + ": cannot open as an LCM log";
    return result;
  }
  robot_state::StateHistory history(whole_log_history(settings));
  int joint_states = 0;
  const std::vector<depth_image_t> frames = read_log(settings, &log, &history, &joint_states);
  result.frames_in_log = static_cast<int>(frames.size());
  if (frames.empty()) {
    result.error =
        log_path + ": no " + settings.channels.depth + " frames of camera '" + settings.camera.id + "'";
    return result;
  }
  if (joint_states == 0) {
    result.error =
        log_path + ": no " + settings.channels.joint_state + " messages of robot '" + settings.robot.id + "'";
    return result;
  }

  const robot_model::SceneModel scene = load_estimator_scene(settings);
  result.error = camera_frame_error(scene, settings);
  if (!result.error.empty()) return result;

  const std::vector<Candidate> candidates = candidates_of(frames, history);
  const std::vector<const Candidate*> chosen = most_diverse(candidates, options);
  result.frames_used = static_cast<int>(chosen.size());
  if (result.frames_used < options.min_frames) {
    result.error =
        log_path + ": too few frames with distinct arm poses (" + std::to_string(result.frames_used) +
        " at least " + std::to_string(options.min_pose_distance_rad) + " rad apart, of " +
        std::to_string(frames.size()) + " frames; need " + std::to_string(options.min_frames) + ")";
    return result;
  }

  const robot_model::LinkPoses static_poses = robot_model::forward_kinematics(scene, chosen.front()->joints);
  if (!static_poses.usable) {
    result.error = static_poses.unusable_reason;
    return result;
  }
  const Eigen::Isometry3d frame_from_optical = settings.camera.pose.frame_from_optical();
  const Eigen::Isometry3d world_from_optical =
      static_poses.world_from_link[scene.find_link(settings.camera.pose.frame_id)] * frame_from_optical;

  renderer::DepthRenderer renderer(scene, settings.renderer.near_m, settings.renderer.far_m);
  MotionEstimator estimator(scene, &renderer, calibration_estimator_options(settings, options));
  const EstimateResult estimate = estimator.estimate_camera(estimator_frames_of(chosen, world_from_optical));
  if (!estimate.usable) {
    result.error = "cannot estimate the camera pose: " + estimate.unusable_reason;
    return result;
  }
  store_estimate(estimate, frame_from_optical, settings, &result);
  return result;
}

}  // namespace tofguard::estimator
