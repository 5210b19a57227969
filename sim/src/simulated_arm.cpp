#include "tofguard/sim/simulated_arm.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace tofguard::sim {

SimulatedArm::SimulatedArm(const JointsSimSettings& config, const std::vector<std::string>& urdf_joints,
                           const std::string& config_file) {
  auto error = [&](const std::string& key, const std::string& what) {
    return ConfigError(config_file + ": joints_sim." + key + ": " + what);
  };
  std::string all;
  for (const auto& j : urdf_joints) all += (all.empty() ? "" : ", ") + j;
  for (const auto& m : config.motion) {
    if (std::find(urdf_joints.begin(), urdf_joints.end(), m.joint) == urdf_joints.end()) {
      throw error("motion." + m.joint, "unknown joint, expected one of the URDF's movable joints: " + all);
    }
  }
  for (const auto& joint : urdf_joints) {
    auto it = std::find_if(config.motion.begin(), config.motion.end(),
                           [&](const JointMotion& m) { return m.joint == joint; });
    if (it == config.motion.end()) {
      throw error("motion",
                  "expected an entry for every movable joint of the URDF (" + all + "), missing " + joint);
    }
    motion_.push_back(*it);
  }
  for (const auto& f : config.faults) {
    if (std::find(urdf_joints.begin(), urdf_joints.end(), f.joint) == urdf_joints.end()) {
      throw error("faults", "unknown joint '" + f.joint + "', expected one of: " + all);
    }
  }
  scheduled_faults_ = config.faults;
  for (const auto& m : motion_) {
    true_state_.name.push_back(m.joint);
    offsets_[m.joint] = 0;
  }
  true_state_.position.resize(motion_.size());
  true_state_.velocity.resize(motion_.size());
  update_state(false);
}

void SimulatedArm::update_state(bool moving) {
  moving_ = moving;
  for (size_t i = 0; i < motion_.size(); ++i) {
    const JointMotion& m = motion_[i];
    const double w = 2 * M_PI / m.period_s;
    const double phase = w * motion_time_s_ + m.phase_rad;
    true_state_.position[i] = m.center + m.amplitude * std::sin(phase);
    true_state_.velocity[i] = moving ? speed_scale_ * m.amplitude * w * std::cos(phase) : 0.0;
  }
}

void SimulatedArm::step(double dt_s, bool motion_allowed, double speed_scale) {
  elapsed_s_ += dt_s;
  speed_scale_ = std::clamp(speed_scale, 0.0, 1.0);
  if (motion_allowed) motion_time_s_ += speed_scale_ * dt_s;
  for (auto it = scheduled_faults_.begin(); it != scheduled_faults_.end();) {
    if (elapsed_s_ >= it->at_s) {
      offsets_[it->joint] = it->offset;
      ++offsets_version_;
      it = scheduled_faults_.erase(it);
    } else {
      ++it;
    }
  }
  update_state(motion_allowed);
}

bool SimulatedArm::set_encoder_offset(const std::string& joint, double offset) {
  auto it = offsets_.find(joint);
  if (it == offsets_.end()) return false;
  it->second = offset;
  ++offsets_version_;
  return true;
}

ArmState SimulatedArm::reported_state() const {
  ArmState reported = true_state_;
  for (size_t i = 0; i < reported.name.size(); ++i) {
    reported.position[i] += offsets_.at(reported.name[i]);
  }
  return reported;
}

std::vector<double> SimulatedArm::planned_reported_positions(double ahead_s) const {
  std::vector<double> positions(motion_.size());
  const double t = motion_time_s_ + (moving_ ? speed_scale_ * ahead_s : 0.0);
  for (size_t i = 0; i < motion_.size(); ++i) {
    const JointMotion& m = motion_[i];
    positions[i] =
        m.center + m.amplitude * std::sin(2 * M_PI / m.period_s * t + m.phase_rad) + offsets_.at(m.joint);
  }
  return positions;
}

}  // namespace tofguard::sim
