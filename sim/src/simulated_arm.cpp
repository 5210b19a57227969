#include "tofguard/sim/simulated_arm.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace tofguard::sim {
namespace {

// The task's waypoints in URDF order; a ConfigError (from `error`) unless
// each gives exactly the URDF's movable joints.
template <class Error>
std::vector<std::vector<double>> task_positions(const JointsSimSettings& config,
                                                const std::vector<std::string>& urdf_joints,
                                                const std::string& all, const Error& error) {
  if (config.task_waypoints.empty()) throw error("task", "a task (waypoints and move_s) for --task");
  std::vector<std::vector<double>> out;
  for (const TaskWaypoint& w : config.task_waypoints) {
    const std::string key = "task.waypoints[" + w.name + "].joints";
    if (w.joints.size() != urdf_joints.size()) {
      throw error(key, "every movable joint of the URDF (" + all + "), " + std::to_string(w.joints.size()) +
                           " given");
    }
    std::vector<double> q;
    for (const auto& joint : urdf_joints) {
      const auto it = w.joints.find(joint);
      if (it == w.joints.end())
        throw error(key, "every movable joint of the URDF (" + all + "), missing " + joint);
      q.push_back(it->second);
    }
    out.push_back(q);
  }
  return out;
}

}  // namespace

SimulatedArm::SimulatedArm(const JointsSimSettings& config, const std::vector<std::string>& urdf_joints,
                           const std::string& config_file, bool task) {
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
  if (task) {
    task_positions_ = task_positions(config, urdf_joints, all, error);
    for (const TaskWaypoint& w : config.task_waypoints) {
      task_hold_s_.push_back(w.hold_s);
      task_names_.push_back(w.name);
    }
    task_move_s_ = config.task_move_s;
  }
  scheduled_faults_ = config.faults;
  for (const auto& m : motion_) {
    true_state_.name.push_back(m.joint);
    offsets_[m.joint] = 0;
  }
  true_state_.position.resize(motion_.size());
  true_state_.velocity.resize(motion_.size());
  driven_.assign(motion_.size(), 0.0);
  update_state(false);
}

double SimulatedArm::task_cycle_s() const {
  double cycle_s = 0;
  for (double hold : task_hold_s_) cycle_s += hold + task_move_s_;
  return cycle_s;
}

SimulatedArm::TaskPhase SimulatedArm::task_phase(double t_s) const {
  double t = std::fmod(t_s, task_cycle_s());
  const size_t n = task_positions_.size();
  for (size_t k = 0; k < n; ++k) {
    if (t < task_hold_s_[k]) return {k, k, 0, 0};
    t -= task_hold_s_[k];
    if (t < task_move_s_) {
      // Cosine speed profile: at rest at both waypoints.
      const double x = t / task_move_s_;
      return {k, (k + 1) % n, (1 - std::cos(M_PI * x)) / 2, M_PI / (2 * task_move_s_) * std::sin(M_PI * x)};
    }
    t -= task_move_s_;
  }
  return {0, 0, 0, 0};
}

double SimulatedArm::drive_velocity(size_t i) const {
  if (static_cast<int>(i) == drive_index_) return drive_rad_s_;
  if (driven_[i] == 0) return 0;
  return driven_[i] > 0 ? -kDriveReturnRadS * speed_scale_ : kDriveReturnRadS * speed_scale_;
}

double SimulatedArm::driven_after(size_t i, double dt_s) const {
  if (static_cast<int>(i) == drive_index_) return driven_[i] + drive_rad_s_ * dt_s;
  const double left = std::max(0.0, std::abs(driven_[i]) - kDriveReturnRadS * speed_scale_ * dt_s);
  return std::copysign(left, driven_[i]);
}

std::string SimulatedArm::task_stage() const {
  if (task_positions_.empty()) return "";
  const TaskPhase p = task_phase(motion_time_s_);
  return (p.from == p.to ? "at " : "to ") + task_names_[p.to];
}

double SimulatedArm::position_at(size_t i, double t_s) const {
  if (!task_positions_.empty()) {
    const TaskPhase p = task_phase(t_s);
    const double a = task_positions_[p.from][i];
    return a + (task_positions_[p.to][i] - a) * p.blend;
  }
  const JointMotion& m = motion_[i];
  return m.center + m.amplitude * std::sin(2 * M_PI / m.period_s * t_s + m.phase_rad);
}

double SimulatedArm::velocity_at(size_t i, double t_s) const {
  if (!task_positions_.empty()) {
    const TaskPhase p = task_phase(t_s);
    return (task_positions_[p.to][i] - task_positions_[p.from][i]) * p.blend_rate;
  }
  const JointMotion& m = motion_[i];
  const double w = 2 * M_PI / m.period_s;
  return m.amplitude * w * std::cos(w * t_s + m.phase_rad);
}

void SimulatedArm::update_state(bool moving) {
  moving_ = moving;
  for (size_t i = 0; i < motion_.size(); ++i) {
    true_state_.position[i] = position_at(i, motion_time_s_) + driven_[i];
    true_state_.velocity[i] =
        moving ? speed_scale_ * velocity_at(i, motion_time_s_) + drive_velocity(i) : 0.0;
  }
}

void SimulatedArm::step(double dt_s, bool motion_allowed, double speed_scale) {
  elapsed_s_ += dt_s;
  speed_scale_ = std::clamp(speed_scale, 0.0, 1.0);
  if (motion_allowed) motion_time_s_ += speed_scale_ * dt_s;
  if (motion_allowed) {
    for (size_t i = 0; i < driven_.size(); ++i) driven_[i] = driven_after(i, dt_s);
  }
  for (auto it = scheduled_faults_.begin(); it != scheduled_faults_.end();) {
    if (elapsed_s_ >= it->at_s) {
      offsets_[it->joint] = it->offset;
      ++plan_version_;
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
  ++plan_version_;
  return true;
}

bool SimulatedArm::set_drive(const std::string& joint, double rad_s) {
  int index = -1;
  for (size_t i = 0; i < motion_.size() && !joint.empty(); ++i) {
    if (motion_[i].joint == joint) index = static_cast<int>(i);
  }
  if (!joint.empty() && index < 0) return false;
  drive_index_ = index;
  drive_rad_s_ = index >= 0 ? rad_s : 0.0;
  ++plan_version_;
  update_state(moving_);
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
  for (size_t i = 0; i < motion_.size(); ++i)
    positions[i] =
        position_at(i, t) + (moving_ ? driven_after(i, ahead_s) : driven_[i]) + offsets_.at(motion_[i].joint);
  return positions;
}

}  // namespace tofguard::sim
