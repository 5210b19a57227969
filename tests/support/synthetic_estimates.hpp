#pragma once
// Synthetic motion estimates and plans for the risk classifier's tests.
#include <cmath>
#include <string>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"

namespace tofguard::test {

constexpr double kDeg = M_PI / 180.0;

// A converged estimate of the FRIEND arm's 7 joints for `frame`: every joint
// observable, reported = estimated = 0.3 rad, sigma 0.2 deg; identity camera
// correction with 2 mm / 0.05 deg sigma; residual 30 -> 6 mm.
inline motion_estimate_t estimate_for(const discrepancy_t& frame) {
  motion_estimate_t e{};
  e.utime = frame.utime;
  e.seq = frame.seq;
  e.camera_id = frame.camera_id;
  e.trigger = motion_estimate_t::TRIGGER_WARNING;
  e.usable = true;
  e.converged = true;
  e.iterations = 6;
  e.num_frames = 1;
  e.joint_name = {"a1", "a2", "a3", "a4", "a5", "a6", "a7"};
  e.num_joints = 7;
  e.reported_position.assign(7, 0.3);
  e.estimated_position.assign(7, 0.3);
  e.position_sigma.assign(7, 0.2 * kDeg);
  e.observable.assign(7, true);
  e.correction_rotation[0] = 1;
  e.correction_translation_sigma_m = 0.002;
  e.correction_rotation_sigma_rad = 0.05 * kDeg;
  e.frame_id = "world";
  e.estimated_rotation[0] = 1;
  e.num_points = 1000;
  e.num_inliers = 950;
  e.residual_before_mm = 30;
  e.residual_after_mm = 6;
  return e;
}

// Index of `joint` in the estimate, -1 when absent.
inline int index_of(const motion_estimate_t& e, const std::string& joint) {
  for (int i = 0; i < e.num_joints; ++i) {
    if (e.joint_name[i] == joint) return i;
  }
  return -1;
}

}  // namespace tofguard::test
