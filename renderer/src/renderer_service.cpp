#include "tofguard/renderer/renderer_service.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/renderer/rendered_occupant.hpp"
#include "tofguard/renderer/state_history_settings.hpp"

namespace tofguard::renderer {

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

std::optional<robot_model::OccupantModel> load_occupant(const std::optional<OccupantSettings>& occupant,
                                                        const robot_model::SceneModel& scene) {
  if (!occupant) return std::nullopt;
  Eigen::Isometry3d world_from_seat;
  try {
    world_from_seat = robot_model::fixed_link_pose(scene, occupant->seated_on);
  } catch (const robot_model::ModelError& e) {
    throw robot_model::ModelError("occupant.seated_on '" + occupant->seated_on + "': " + e.what() +
                                  " (expected a link of the environment)");
  }
  return robot_model::load_occupant(occupant->urdf_path, world_from_seat);
}

}  // namespace

RendererService::RendererService(const RendererProcessSettings& settings)
    : settings_(settings),
      scene_(robot_model::load_scene(settings.robot.urdf_path, settings.environment.urdf_paths,
                                     scene_options(settings.renderer, settings.robot))),
      arm_cover_(robot_model::cover_arm_with_spheres(scene_, settings.renderer.arm_cover_cell_m)),
      occupant_(load_occupant(settings.occupant, scene_)),
      occupant_objects_(occupant_ ? occupant_render_objects(*occupant_) : std::vector<ExtraObject>{}),
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
  p.result = renderer_->render(p.joints, p.pose, p.intrinsics, occupant_objects_);
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
    result = renderer_->render(state.joints.joints, state.camera_pose.pose, intrinsics_of(frame),
                               occupant_objects_);
  }
  // The kinematics and the arm's cover at the frame's own joints and
  // camera pose: the poses a render of them used (no second forward
  // kinematics), or for a prediction (rendered at the plan's joints, within
  // the tolerances) the frame's.
  std::optional<RenderedKinematics> kinematics;
  std::optional<RenderedArmCover> arm_cover;
  std::optional<Eigen::Isometry3d> optical;
  if (result.usable) {
    robot_model::LinkPoses poses;
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
      arm_cover = rendered_arm_cover(arm_cover_, poses, *optical, occupant_ ? &*occupant_ : nullptr);
    }
  }
  RenderedFrame out = make_output(frame, std::move(result), kinematics, arm_cover, optical);
  plan_prediction(frame);
  return out;
}

RenderedFrame RendererService::make_output(const depth_image_t& frame, RenderResult result,
                                           const std::optional<RenderedKinematics>& kinematics,
                                           const std::optional<RenderedArmCover>& arm_cover,
                                           const std::optional<Eigen::Isometry3d>& world_from_optical) const {
  RenderedFrame out;
  if (!result.usable) {
    out.labels =
        make_unusable_link_labels(frame, scene_.num_robot_links, scene_.link_names(), result.unusable_reason);
    return out;
  }
  out.labels = make_link_labels(frame, scene_.num_robot_links, scene_.link_names(), std::move(result.labels));
  if (kinematics) set_rendered_kinematics(*kinematics, &out.labels);
  if (arm_cover) set_rendered_arm_cover(*arm_cover, &out.labels);
  if (world_from_optical) set_rendered_optical_pose(*world_from_optical, &out.labels);
  if (occupant_) {
    // The render drew the occupant (labels kLabelOccupantFirst + shape),
    // so the labels must carry its shapes, or the frame is not usable.
    if (!arm_cover || !world_from_optical) {
      out.labels = make_unusable_link_labels(frame, scene_.num_robot_links, scene_.link_names(),
                                             "no camera pose to place the occupant's shapes in");
      return out;
    }
    set_rendered_occupant(*occupant_, *settings_.occupant, *world_from_optical, &out.labels);
  }
  // The model's depth is exact: calibrated (no distance calibration to
  // apply), no amplitude.
  out.depth = make_depth_image(frame.camera_id, intrinsics_of(frame), frame.utime, frame.seq,
                               /*calibrated=*/true, result.depth_m);
  return out;
}

}  // namespace tofguard::renderer
