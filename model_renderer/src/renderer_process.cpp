#include "renderer_process.hpp"

#include <cmath>
#include <stdexcept>

namespace tofguard::renderer {

ProcessInfo process_info() {
  return {"tofguard-renderer",
          "Renders the arm's model at the reported joint angles from the camera's pose: TOF_DEPTH, JOINT_STATE, "
          "CAMERA_POSE -> TOF_RENDERED, TOF_LABELS.\n"
          "Also: tofguard-renderer render --help (one image to PNG files)."};
}

SceneOptions scene_options(const Config& config) {
  SceneOptions options;
  options.geometry = parse_geometry_source(config.renderer.geometry);
  options.padding_m = config.renderer.padding_m;
  options.package_paths = config.robot.package_paths;
  return options;
}

namespace {

std::unique_ptr<DepthRenderer> make_renderer(const SceneModel& scene, const RendererConfig& config) {
  if (config.far_m > kMaxFarM) {
    throw std::invalid_argument("renderer.far_m must be at most " + std::to_string(kMaxFarM) +
                                " m (depth_mm is int16 millimetres), got " + std::to_string(config.far_m));
  }
  return std::make_unique<DepthRenderer>(scene, config.near_m, config.far_m);
}

}  // namespace

RendererService::RendererService(const Config& config)
    : config_(config),
      scene_(load_scene(config.robot.urdf_path, config.environment.urdf_paths, scene_options(config))),
      renderer_(make_renderer(scene_, config.renderer)),
      history_(static_cast<int64_t>(std::llround(config.renderer.max_extrapolation_ms * 1000.0))),
      camera_poses_(static_cast<int64_t>(std::llround(config.renderer.camera_pose_history_ms * 1000.0)),
                    static_cast<int64_t>(std::llround(config.renderer.camera_pose_max_extrapolation_ms * 1000.0))) {
  camera_poses_.set_static(config.camera.id, config.camera.pose);
}

bool RendererService::on_joint_state(const joint_state_t& state) {
  if (state.robot_id != config_.robot.id) return false;
  JointPositions positions;
  for (int i = 0; i < state.num_joints; ++i) positions[state.name[i]] = state.position[i];
  return history_.add(state.utime, positions);
}

bool RendererService::on_camera_pose(const camera_pose_t& message) {
  CameraPose pose;
  pose.frame_id = message.frame_id;
  pose.translation_m = Eigen::Vector3d(message.translation[0], message.translation[1], message.translation[2]);
  // check_camera_pose allows a norm within 1e-3 of 1: normalise.
  pose.rotation =
      Eigen::Quaterniond(message.rotation[0], message.rotation[1], message.rotation[2], message.rotation[3]).normalized();
  return camera_poses_.add(message.camera_id, message.utime, pose);
}

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

RenderedFrame RendererService::render(const depth_image_t& frame) {
  RenderedFrame out;
  link_labels_t& labels = out.labels;
  labels.utime = frame.utime;
  labels.seq = frame.seq;
  labels.camera_id = frame.camera_id;
  labels.width = frame.width;
  labels.height = frame.height;
  labels.num_robot_links = scene_.num_robot_links;
  labels.link_name = scene_.link_names();
  labels.num_links = static_cast<int32_t>(labels.link_name.size());
  labels.num_pixels = 0;
  labels.usable = false;

  const JointsAtTime joints = history_.at(frame.utime);
  const PoseAtTime pose = camera_poses_.at(frame.camera_id, frame.utime);
  RenderResult result;
  if (!joints.usable) {
    result.unusable_reason = joints.unusable_reason;
  } else if (!pose.usable) {
    result.unusable_reason = pose.unusable_reason;
  } else {
    const Intrinsics intrinsics{frame.width, frame.height, frame.fx, frame.fy, frame.cx, frame.cy};
    result = renderer_->render(joints.joints, pose.pose, intrinsics);
  }
  if (!result.usable) {
    labels.unusable_reason = result.unusable_reason;
    return out;
  }
  labels.usable = true;
  labels.num_pixels = static_cast<int32_t>(result.labels.size());
  labels.label = std::move(result.labels);

  depth_image_t depth;
  depth.utime = frame.utime;
  depth.seq = frame.seq;
  depth.camera_id = frame.camera_id;
  depth.width = frame.width;
  depth.height = frame.height;
  depth.fx = frame.fx;
  depth.fy = frame.fy;
  depth.cx = frame.cx;
  depth.cy = frame.cy;
  depth.calibrated = true;
  depth.num_pixels = static_cast<int32_t>(result.depth_m.size());
  depth.depth_mm.resize(result.depth_m.size());
  for (size_t i = 0; i < result.depth_m.size(); ++i) {
    const double mm = std::round(static_cast<double>(result.depth_m[i]) * 1000.0);
    depth.depth_mm[i] = static_cast<int16_t>(mm > 0 && mm <= 32767 ? mm : 0);
  }
  depth.num_amplitude = 0;
  out.depth = std::move(depth);
  return out;
}

}  // namespace tofguard::renderer
