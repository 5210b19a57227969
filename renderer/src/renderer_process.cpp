#include "tofguard/renderer/renderer_process.hpp"
#include "tofguard/renderer/llvmpipe_threads.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/renderer/state_history_settings.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "tofguard/common/clock.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/resident_heap.hpp"
#include "tofguard/common/wire_checks.hpp"

namespace tofguard::renderer {

ProcessInfo process_info() {
  return {
      "tofguard-renderer",
      "Renders the arm's model at the reported joint angles from the camera's pose: TOF_DEPTH, JOINT_STATE, "
      "CAMERA_POSE, PLANNED_TRAJECTORY (rendering the next frame ahead) -> TOF_RENDERED, TOF_LABELS.\n"
      "Also: tofguard-renderer render --help (one image to PNG files)."};
}

robot_model::SceneOptions scene_options(const RendererSettings& renderer, const RobotSettings& robot) {
  robot_model::SceneOptions options;
  options.geometry = robot_model::parse_geometry_source(renderer.geometry);
  options.padding_m = renderer.padding_m;
  options.simplify_error_m = renderer.simplify_error_mm / 1000.0;
  options.package_paths = robot.package_paths;
  return options;
}

namespace {

std::unique_ptr<DepthRenderer> make_renderer(const robot_model::SceneModel& scene,
                                             const RendererSettings& config) {
  if (config.far_m > kMaxFarM) {
    throw std::invalid_argument("renderer.far_m must be at most " + std::to_string(kMaxFarM) +
                                " m (depth_mm is int16 millimetres), got " + std::to_string(config.far_m));
  }
  return std::make_unique<DepthRenderer>(scene, config.near_m, config.far_m);
}

}  // namespace

RendererService::RendererService(const RendererProcessSettings& settings)
    : settings_(settings),
      scene_(robot_model::load_scene(settings.robot.urdf_path, settings.environment.urdf_paths,
                                     scene_options(settings.renderer, settings.robot))),
      arm_cover_(robot_model::cover_arm_with_spheres(scene_, settings.renderer.arm_cover_cell_m)),
      renderer_(make_renderer(scene_, settings.renderer)),
      state_(state_history_settings(settings.renderer, settings.robot.id, settings.camera)) {}

bool RendererService::on_joint_state(const joint_state_t& state) { return state_.add_joint_state(state); }

bool RendererService::on_camera_pose(const camera_pose_t& message) { return state_.add_camera_pose(message); }

bool RendererService::on_depth(const depth_image_t& frame) {
  const bool dropped = pending_.has_value();
  pending_ = frame;
  return dropped;
}

std::optional<RenderedFrame> RendererService::render_pending() {
  if (!pending_) return std::nullopt;
  const depth_image_t frame = std::move(*pending_);
  pending_.reset();
  return render(frame);
}

namespace {

constexpr double kDegToRad = M_PI / 180.0;
// Frame intervals kept to learn the camera period (their median).
constexpr size_t kKeptIntervals = 9;
// After this many misses in a row, predict only every kProbeEveryFrames-th
// frame until a hit.
constexpr int kMissesBeforeProbing = 5;
constexpr int kProbeEveryFrames = 8;

}  // namespace

void PredictionSchedule::rendered(int64_t duration_us) {
  durations_us_.push_back(duration_us);
  while (durations_us_.size() > kKeptRenders) durations_us_.pop_front();
}

int64_t PredictionSchedule::start_us(int64_t period_us) const {
  if (period_us <= 0 || last_frame_us_ <= 0 || durations_us_.empty()) return 0;
  const int64_t longest_us = *std::max_element(durations_us_.begin(), durations_us_.end());
  return last_frame_us_ + period_us - (longest_us + longest_us / 4 + kMarginUs);
}

std::string RendererService::prediction_status(const PredictionStats& p) {
  return "prediction: " + std::to_string(p.hits) + " hits, " + std::to_string(p.misses) + " misses, " +
         std::to_string(p.without) + " frames without one, " + std::to_string(p.rendered) + " rendered ahead";
}

std::optional<RendererService::PredictionStats> RendererService::prediction_stats_from_status(
    const std::string& status) {
  const size_t at = status.find("prediction: ");
  if (at == std::string::npos) return std::nullopt;
  long long hits = 0, misses = 0, without = 0, rendered = 0;
  if (std::sscanf(status.c_str() + at,
                  "prediction: %lld hits, %lld misses, %lld frames without one, %lld rendered ahead", &hits,
                  &misses, &without, &rendered) != 4)
    return std::nullopt;
  PredictionStats p;
  p.hits = hits;
  p.misses = misses;
  p.without = without;
  p.rendered = rendered;
  return p;
}

void RendererService::on_plan(const planned_trajectory_t& plan) { plan_.add(plan); }

// The median of the kept intervals, learned once per frame: the process
// asks for it at every idle wake-up (PredictionSchedule).
void RendererService::learn_period(const depth_image_t& frame) {
  if (last_frame_utime_ && frame.utime > *last_frame_utime_) {
    frame_intervals_us_.push_back(frame.utime - *last_frame_utime_);
    while (frame_intervals_us_.size() > kKeptIntervals) frame_intervals_us_.pop_front();
    std::vector<int64_t> sorted(frame_intervals_us_.begin(), frame_intervals_us_.end());
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    frame_period_us_ = sorted[sorted.size() / 2];
  }
  last_frame_utime_ = frame.utime;
}

void RendererService::plan_prediction(const depth_image_t& frame) {
  prediction_.reset();
  const int64_t period_us = frame_period_us();
  if (!settings_.renderer.prediction_enabled || period_us <= 0) return;
  if (consecutive_misses_ >= kMissesBeforeProbing && ++frames_since_probe_ < kProbeEveryFrames) return;
  frames_since_probe_ = 0;
  const int64_t utime = frame.utime + period_us;
  Prediction p;
  p.camera_id = frame.camera_id;
  p.utime = utime;
  p.intrinsics = intrinsics_of(frame);
  const auto planned = plan_.at(utime);
  if (planned && covers_actuated_joints(*planned)) {
    for (const std::string& joint : scene_.actuated_joint_names) p.joints[joint] = planned->at(joint);
  } else if (settings_.renderer.prediction_from_joint_states) {
    // The joints are guessed when the render ahead starts, from the joint
    // states there are by then (render_prediction).
    p.from_joint_states = true;
  } else {
    return;  // no plan for that time, or one that does not cover the model
  }
  // The pose for that time now; a moving camera's later reading may differ
  // (then the frame is a miss).
  const robot_state::PoseAtTime pose = state_.camera_poses().at(frame.camera_id, utime);
  if (!pose.usable) return;
  p.pose = pose.pose;
  prediction_ = std::move(p);
}

bool RendererService::covers_actuated_joints(const robot_model::JointPositions& joints) const {
  for (const std::string& joint : scene_.actuated_joint_names) {
    if (joints.find(joint) == joints.end()) return false;
  }
  return true;
}

bool RendererService::has_prediction_to_render() const {
  if (!prediction_ || prediction_->rendered) return false;
  // A guess from the joint states that had to wait waits for a newer one.
  return !prediction_->joints_wanted_after_utime ||
         state_.joints().newest_utime() != prediction_->joints_wanted_after_utime;
}

bool RendererService::render_prediction() {
  if (!has_prediction_to_render()) return false;
  Prediction& p = *prediction_;
  if (p.from_joint_states) {
    // Linear through the two newest joint states (interpolated when they
    // already bracket the frame's utime), at most one camera period beyond
    // the newest: a joint stream slower than the camera, or one that has
    // stopped, predicts nothing.
    robot_state::JointsAtTime guess = state_.joints().at(p.utime, frame_period_us_);
    if (!guess.usable || !covers_actuated_joints(guess.joints)) {
      p.joints_wanted_after_utime = state_.joints().newest_utime();
      return false;
    }
    p.joints = std::move(guess.joints);
  }
  p.result = renderer_->render(p.joints, p.pose, p.intrinsics);
  p.rendered = true;
  prediction_stats_.rendered++;
  return true;
}

bool RendererService::prediction_matches(const depth_image_t& frame,
                                         const robot_model::JointPositions& joints,
                                         const CameraPose& pose) const {
  const Prediction& p = *prediction_;
  if (!p.rendered || !p.result.usable || p.camera_id != frame.camera_id ||
      p.intrinsics.width != frame.width || p.intrinsics.height != frame.height ||
      p.intrinsics.fx != frame.fx || p.intrinsics.fy != frame.fy || p.intrinsics.cx != frame.cx ||
      p.intrinsics.cy != frame.cy) {
    return false;
  }
  const RendererSettings& r = settings_.renderer;
  for (const auto& [joint, predicted] : p.joints) {
    const auto actual = joints.find(joint);
    if (actual == joints.end()) return false;
    const double tolerance = scene_.is_prismatic_joint(joint) ? r.prediction_joint_tolerance_m
                                                              : r.prediction_joint_tolerance_deg * kDegToRad;
    if (!(std::abs(actual->second - predicted) <= tolerance)) return false;
  }
  return pose.frame_id == p.pose.frame_id &&
         (pose.translation_m - p.pose.translation_m).norm() <= r.prediction_pose_tolerance_mm / 1000.0 &&
         pose.rotation.angularDistance(p.pose.rotation) <= r.prediction_pose_tolerance_deg * kDegToRad;
}

RenderedFrame RendererService::render(const depth_image_t& frame) {
  learn_period(frame);
  const robot_state::StateAtFrame state = state_.at(frame.camera_id, frame.utime);
  RenderResult result;
  bool predicted = false;
  if (!state.usable()) {
    result.unusable_reason = state.unusable_reason();
  } else if (prediction_ && prediction_matches(frame, state.joints.joints, state.camera_pose.pose)) {
    prediction_stats_.hits++;
    consecutive_misses_ = 0;
    result = std::move(prediction_->result);
    predicted = true;
  } else {
    const bool missed = prediction_ && prediction_->rendered;
    (missed ? prediction_stats_.misses : prediction_stats_.without)++;
    if (missed) ++consecutive_misses_;
    result = renderer_->render(state.joints.joints, state.camera_pose.pose, intrinsics_of(frame));
  }
  // The kinematics and the arm's cover at the frame's own joints and
  // camera pose: the poses a render of them used (no second forward
  // kinematics), or for a prediction (rendered at the plan's joints, within
  // the tolerances) the frame's.
  std::optional<RenderedKinematics> kinematics;
  std::optional<RenderedArmCover> arm_cover;
  if (result.usable) {
    robot_model::LinkPoses poses;
    std::optional<Eigen::Isometry3d> optical;
    if (predicted) {
      poses = robot_model::forward_kinematics(scene_, state.joints.joints);
      optical = world_from_optical(scene_, poses, state.camera_pose.pose);
    }
    if (!optical && result.world_from_link.size() == scene_.links.size()) {
      poses.usable = true;
      poses.world_from_link = result.world_from_link;
      optical = result.world_from_optical;
    }
    if (optical) {
      kinematics = rendered_kinematics(scene_, poses, *optical);
      arm_cover = rendered_arm_cover(arm_cover_, poses, *optical);
    }
  }
  RenderedFrame out = make_output(frame, std::move(result), kinematics, arm_cover);
  plan_prediction(frame);
  return out;
}

RenderedFrame RendererService::make_output(const depth_image_t& frame, RenderResult result,
                                           const std::optional<RenderedKinematics>& kinematics,
                                           const std::optional<RenderedArmCover>& arm_cover) const {
  RenderedFrame out;
  if (!result.usable) {
    out.labels =
        make_unusable_link_labels(frame, scene_.num_robot_links, scene_.link_names(), result.unusable_reason);
    return out;
  }
  out.labels = make_link_labels(frame, scene_.num_robot_links, scene_.link_names(), std::move(result.labels));
  if (kinematics) set_rendered_kinematics(*kinematics, &out.labels);
  if (arm_cover) set_rendered_arm_cover(*arm_cover, &out.labels);
  // The model's depth is exact: calibrated (no distance calibration to
  // apply), no amplitude.
  out.depth = make_depth_image(frame.camera_id, intrinsics_of(frame), frame.utime, frame.seq,
                               /*calibrated=*/true, result.depth_m);
  return out;
}

int run_renderer(const RendererProcessSettings& settings) {
  if (!keep_heap_resident())
    std::fprintf(stderr, "tofguard-renderer: warning: mallopt refused keep_heap_resident's settings\n");
  const std::string name = process_info().name;
  // Before the service opens its EGL display (llvmpipe reads it then).
  std::cerr << name << ": " << choose_llvmpipe_threads(settings.camera.intrinsics) << "\n";
  std::unique_ptr<RendererService> service;
  try {
    service = std::make_unique<RendererService>(settings);
  } catch (const std::exception& e) {
    // A model that cannot be rendered is a configuration error: nothing is
    // published, so the risk chain sees this process's heartbeat missing.
    std::cerr << name << ": " << e.what() << "\n";
    return kConfigErrorExitCode;
  }
  std::cerr << name << ": rendering with " << service->description() << "\n";
  LcmNode node(settings.lcm, settings.channels, name);
  node.heartbeat().set_status("waiting for frames");

  node.subscribe<joint_state_t>(
      node.safety(), settings.channels.joint_state,
      [&](const joint_state_t& state) {
        if (!service->on_joint_state(state)) {
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
      [&](const camera_pose_t& pose) {
        if (!service->on_camera_pose(pose)) {
          node.counters().validation_errors++;
          node.errors().report(settings.channels.camera_pose,
                               settings.channels.camera_pose +
                                   ": utime: expected a pose newer than camera '" + pose.camera_id +
                                   "''s newest, got " + std::to_string(pose.utime) + "; ignored");
        }
      },
      check_camera_pose);
  node.subscribe<planned_trajectory_t>(
      node.safety(), settings.channels.planned_trajectory,
      [&](const planned_trajectory_t& plan) { service->on_plan(plan); }, check_planned_trajectory);
  PredictionSchedule schedule;
  node.subscribe<depth_image_t>(
      node.images(), settings.channels.depth,
      [&](const depth_image_t& frame) {
        schedule.frame_arrived(monotonic_us());
        if (service->on_depth(frame)) node.counters().frames_dropped++;
      },
      check_depth_image);

  // Before rendering, take in everything that has already arrived, so that
  // the newest joint states and only the newest frame are used (bounded, so
  // that a flood cannot starve the rendering).
  const auto drain = [&] {
    for (int i = 0; i < 1000; ++i) {
      const bool safety = node.safety().handleTimeout(0) > 0;
      const bool images = &node.images() != &node.safety() && node.images().handleTimeout(0) > 0;
      if (!safety && !images) return;
    }
  };
  auto status = [&](const std::string& what) {
    node.heartbeat().set_status(what + "; " +
                                RendererService::prediction_status(service->prediction_stats()));
  };
  // Idle: how long to wait for messages before the render ahead is due.
  const auto idle_wait_ms = [&]() -> int {
    if (!service->has_prediction_to_render()) return 20;
    const int64_t left_us = schedule.start_us(service->frame_period_us()) - monotonic_us();
    return left_us <= 0 ? 0 : static_cast<int>(std::min<int64_t>(20, (left_us + 999) / 1000));
  };
  while (node.spin_once(service->has_pending() ? 0 : idle_wait_ms())) {
    if (!service->has_pending()) {
      // Idle: render the next frame ahead (from the plan, else from the
      // joint states) when it is due (no wait left), unless a frame has
      // come meanwhile. A guess from the joint states that finds them too
      // old waits for the next one (the wait above ends with any message).
      drain();
      if (!service->has_pending() && service->has_prediction_to_render() && idle_wait_ms() == 0) {
        const int64_t start_us = monotonic_us();
        if (service->render_prediction()) schedule.rendered(monotonic_us() - start_us);
      }
      continue;
    }
    drain();
    const std::optional<RenderedFrame> rendered = service->render_pending();
    if (!rendered) continue;
    node.images().publish(settings.channels.labels, &rendered->labels);
    if (rendered->depth) node.images().publish(settings.channels.rendered, &*rendered->depth);
    node.counters().frames_out++;
    node.heartbeat().set_last_frame_utime(rendered->labels.utime);
    status(rendered->labels.usable ? "rendering" : "frame unusable: " + rendered->labels.unusable_reason);
    if (!rendered->labels.usable)
      node.errors().report("unusable", "frame unusable: " + rendered->labels.unusable_reason);
  }
  return 0;
}

}  // namespace tofguard::renderer
