#pragma once
// A simulated joint's periodic motion (sim::JointMotion, as joints_sim moves
// it) at motion time `t_s`, for the test tools that prepare frames along the
// arm's path without running the simulated arm.
#include <cmath>

#include "tofguard/settings/sim_settings.hpp"

namespace tofguard::test {

// center + amplitude * sin(2*pi*t/period_s + phase): rad (or m).
inline double joint_position(const sim::JointMotion& m, double t_s) {
  constexpr double kPi = 3.141592653589793;
  return m.center + m.amplitude * std::sin(2 * kPi * t_s / m.period_s + m.phase_rad);
}

// Its time derivative: rad/s (or m/s).
inline double joint_velocity(const sim::JointMotion& m, double t_s) {
  constexpr double kPi = 3.141592653589793;
  return m.amplitude * 2 * kPi / m.period_s * std::cos(2 * kPi * t_s / m.period_s + m.phase_rad);
}

}  // namespace tofguard::test
