#include "tofguard/sim/sim_camera.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace tofguard::sim {
namespace {

constexpr int64_t kMaxExtrapolationUs = 50000;

}  // namespace

bool SimulatedCamera::add_true_joint_state(int64_t utime, const std::vector<std::string>& names,
                                           const std::vector<double>& positions) {
  robot_model::JointPositions joints;
  for (size_t i = 0; i < names.size() && i < positions.size(); ++i) joints[names[i]] = positions[i];
  return joints_.add(utime, joints);
}

SimulatedCamera::SimulatedCamera(const CameraSettings& camera, const SimCameraSettings& sim,
                                 SceneRenderer* renderer, int64_t start_utime,
                                 std::optional<SimulatedUser> user)
    : camera_(camera),
      sim_(sim),
      renderer_(renderer),
      start_utime_(start_utime),
      model_(sim, camera.intrinsics),
      joints_(kMaxExtrapolationUs),
      user_(std::move(user)) {
  for (const SimCameraFaultSettings& f : sim.faults) {
    const int64_t start = start_utime + f.start_us;
    faults_.push_back({f, start, start + f.duration_us});
  }
}

void SimulatedCamera::clear_faults(int64_t utime) {
  for (ActiveSimFault& f : faults_) f.end_utime = std::min(f.end_utime, utime);
}

CameraPose SimulatedCamera::turned_pose(double pan_rad, double tilt_rad) const {
  CameraPose pose = camera_.pose;
  pose.rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(pan_rad, Eigen::Vector3d::UnitZ())) * pose.rotation *
                   Eigen::Quaterniond(Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitX())))
                      .normalized();
  return pose;
}

double SimulatedCamera::true_pan_rad(int64_t utime) const {
  if (!sim_.pan_tilt_enabled) return 0;
  const double t = (utime - start_utime_) * 1e-6;
  return sim_.pan_amplitude_rad * std::sin(2 * M_PI * t / sim_.pan_period_s);
}

double SimulatedCamera::true_tilt_rad(int64_t utime) const {
  if (!sim_.pan_tilt_enabled) return 0;
  const double t = (utime - start_utime_) * 1e-6;
  return sim_.tilt_amplitude_rad * std::sin(2 * M_PI * t / sim_.tilt_period_s);
}

std::optional<CameraPose> SimulatedCamera::reported_pose(int64_t utime) const {
  if (!sim_.pan_tilt_enabled) return std::nullopt;
  double pan = true_pan_rad(utime);
  double tilt = true_tilt_rad(utime);
  for (const ActiveSimFault& f : faults_) {
    if (f.fault.kind != "pan_tilt_offset" || !active(f, utime)) continue;
    pan += f.fault.pan_offset_rad;
    tilt += f.fault.tilt_offset_rad;
  }
  return turned_pose(pan, tilt);
}

CameraPose SimulatedCamera::true_pose(int64_t utime) const {
  CameraPose pose = turned_pose(true_pan_rad(utime), true_tilt_rad(utime));
  for (const ActiveSimFault& f : faults_) {
    if (f.fault.kind != "pose_drift" || utime < f.start_utime) continue;
    // The drift accumulates while the fault lasts and stays afterwards (a
    // knocked camera does not move back by itself).
    const double dt = (std::min(utime, f.end_utime) - f.start_utime) * 1e-6;
    pose.translation_m += f.fault.drift_translation_m_per_s * dt;
    const Eigen::Vector3d rotation = f.fault.drift_rotation_rad_per_s * dt;
    if (rotation.norm() > 0) {
      // About the optical frame's own axes: applied on the right.
      pose.rotation =
          pose.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(rotation.norm(), rotation.normalized()));
    }
  }
  return pose;
}

std::vector<SimBox> SimulatedCamera::boxes(int64_t utime) const {
  std::vector<SimBox> out;
  for (const ActiveSimFault& f : faults_) {
    if (f.fault.kind != "intruding_object" || !active(f, utime)) continue;
    SimBox box;
    box.size_m = f.fault.object_size_m;
    box.center_m =
        f.fault.object_position_m + f.fault.object_velocity_m_per_s * ((utime - f.start_utime) * 1e-6);
    out.push_back(box);
  }
  return out;
}

std::vector<RegionShape> SimulatedCamera::user_shapes(int64_t utime) const {
  if (!user_) return {};
  return user_->shapes_at(std::max<int64_t>(0, utime - start_utime_) * 1e-6);
}

SimulatedCamera::Frame SimulatedCamera::capture(int64_t utime, uint64_t frame_index) {
  Frame frame;
  for (const ActiveSimFault& f : faults_) {
    if (f.fault.kind == "stall" && active(f, utime)) {
      frame.outcome = Frame::Outcome::kStalled;
      frame.why = "stall fault injected";
      return frame;
    }
  }
  for (const ActiveSimFault& f : faults_) {
    if (f.fault.kind == "frozen_image" && active(f, utime) && last_image_) {
      frame.image = *last_image_;
      frame.frozen = true;
      return frame;
    }
  }
  const robot_state::JointsAtTime joints = joints_.at(utime);
  if (!joints.usable) {
    frame.outcome = Frame::Outcome::kNoJointState;
    frame.why = "true joint state: " + joints.unusable_reason;
    return frame;
  }
  const RenderedDepth rendered = renderer_->render(joints.joints, true_pose(utime), camera_.intrinsics,
                                                   boxes(utime), user_shapes(utime));
  if (!rendered.usable) {
    frame.outcome = Frame::Outcome::kRenderFailed;
    frame.why = "render failed: " + rendered.unusable_reason;
    return frame;
  }
  // The camera's own running time, for its warm-up drift.
  const double time_since_start_s = std::max<int64_t>(0, utime - start_utime_) * 1e-6;
  frame.image = model_.apply(rendered.depth_m, frame_index, time_since_start_s);
  last_image_ = frame.image;
  return frame;
}

}  // namespace tofguard::sim
