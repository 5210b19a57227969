#include "sim_camera.hpp"

#include <cmath>

namespace tofguard::camera {
namespace {

constexpr int64_t kMaxExtrapolationUs = 50000;

int64_t seconds_to_us(double s) { return static_cast<int64_t>(std::llround(s * 1e6)); }

}  // namespace

bool TrueJointHistory::add(int64_t utime, const std::vector<std::string>& names,
                           const std::vector<double>& positions,
                           const std::vector<double>& velocities) {
  if (!states_.empty() && utime <= states_.back().utime) return false;
  State s;
  s.utime = utime;
  for (size_t i = 0; i < names.size() && i < positions.size(); ++i) {
    s.position[names[i]] = positions[i];
    s.velocity[names[i]] = i < velocities.size() ? velocities[i] : 0.0;
  }
  states_.push_back(std::move(s));
  while (states_.size() > 2 && states_.front().utime < utime - keep_us_) states_.pop_front();
  return true;
}

std::optional<std::map<std::string, double>> TrueJointHistory::at(int64_t utime,
                                                                   int64_t max_extrapolation_us,
                                                                   std::string* why) const {
  if (states_.empty()) {
    *why = "no true joint state received yet";
    return std::nullopt;
  }
  const State& newest = states_.back();
  if (utime >= newest.utime) {
    const int64_t ahead_us = utime - newest.utime;
    if (ahead_us > max_extrapolation_us) {
      *why = "newest true joint state is " + std::to_string(ahead_us / 1000) +
             " ms older than the frame (more than " + std::to_string(max_extrapolation_us / 1000) +
             " ms)";
      return std::nullopt;
    }
    std::map<std::string, double> out = newest.position;
    for (auto& [name, q] : out) q += newest.velocity.at(name) * ahead_us * 1e-6;
    return out;
  }
  if (utime < states_.front().utime) {
    *why = "capture time before the oldest true joint state kept";
    return std::nullopt;
  }
  for (size_t i = states_.size() - 1; i > 0; --i) {
    const State& a = states_[i - 1];
    const State& b = states_[i];
    if (utime < a.utime) continue;
    const double t = static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime);
    std::map<std::string, double> out;
    for (const auto& [name, qa] : a.position) {
      const auto it = b.position.find(name);
      // A joint missing from one state stays missing: the renderer then
      // refuses the frame instead of drawing the arm wrong.
      if (it != b.position.end()) out[name] = qa + t * (it->second - qa);
    }
    return out;
  }
  *why = "no true joint states around the frame";
  return std::nullopt;
}

SimulatedCamera::SimulatedCamera(const CameraConfig& config, SceneRenderer* renderer,
                                 int64_t start_utime)
    : config_(config), renderer_(renderer), model_(config.sim, config.intrinsics) {
  for (const SimCameraFaultConfig& f : config.sim.faults) {
    const int64_t start = start_utime + seconds_to_us(f.start_s);
    faults_.push_back({f, start, start + seconds_to_us(f.duration_s)});
  }
}

void SimulatedCamera::clear_faults(int64_t utime) {
  for (ActiveSimFault& f : faults_) f.end_utime = std::min(f.end_utime, utime);
}

CameraPose SimulatedCamera::true_pose(int64_t utime) const {
  CameraPose pose = config_.pose;
  for (const ActiveSimFault& f : faults_) {
    if (f.fault.kind != "pose_drift" || utime < f.start_utime) continue;
    // The drift accumulates while the fault lasts and stays afterwards (a
    // knocked camera does not move back by itself).
    const double dt = (std::min(utime, f.end_utime) - f.start_utime) * 1e-6;
    pose.translation_m += f.fault.drift_translation_m_per_s * dt;
    const Eigen::Vector3d rotation = f.fault.drift_rotation_rad_per_s * dt;
    if (rotation.norm() > 0) {
      // About the optical frame's own axes: applied on the right.
      pose.rotation = pose.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(
                                          rotation.norm(), rotation.normalized()));
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
  const auto joints = joints_.at(utime, kMaxExtrapolationUs, &frame.why);
  if (!joints) {
    frame.outcome = Frame::Outcome::kNoJointState;
    return frame;
  }
  const RenderedDepth rendered = renderer_->render(*joints, true_pose(utime), config_.intrinsics,
                                                   boxes(utime));
  if (!rendered.usable) {
    frame.outcome = Frame::Outcome::kRenderFailed;
    frame.why = "render failed: " + rendered.unusable_reason;
    return frame;
  }
  frame.image = model_.apply(rendered.depth_m, frame_index);
  last_image_ = frame.image;
  return frame;
}

}  // namespace tofguard::camera
