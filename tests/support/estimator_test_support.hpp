#pragma once
// The estimator tests' scene: config/sim.yaml's arm, environment and
// 176x144 camera, frames from the simulated ToF camera (noise, mixed and
// invalid pixels, calibrated like tofguard-camera publishes them).
#include <cmath>
#include <memory>

#include "simulated_frames.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/estimator/motion_estimator.hpp"
#include "tool_support.hpp"

namespace tofguard::estimator::test {

inline double deg(double degrees) { return degrees * M_PI / 180.0; }
inline double to_deg(double radians) { return radians * 180.0 / M_PI; }

// config/sim.yaml with its camera ideal: the estimator tests make their own frames.
inline deployment::Config sim_config() {
  return deployment::load_config(tofguard::test::ideal_camera_config(), nullptr);
}

inline Eigen::Isometry3d pose_of(const CameraPose& pose) { return pose.frame_from_optical(); }

// The arm's test poses (radians), joints a1..a7. Each keeps every joint's
// distal links in view and bent away from the joint's axis (a3, a5 and a7
// turn cylinders about their own axes: only the bent links after them show
// their angle).
inline robot_model::JointPositions reach_pose() {
  // The simulated arm's centre pose (config/sim.yaml joints_sim): reaching
  // forward over the table, elbow bent, wrist bent.
  return {{"a1", -0.30}, {"a2", 0.70}, {"a3", 0.0}, {"a4", 1.10}, {"a5", 0.0}, {"a6", 0.60}, {"a7", 0.0}};
}

// Reaching down and to the right over the table's near edge, upper arm
// nearly level, forearm and wrist bent down, the gripper turned: every link
// in view, seen from the side rather than end-on.
inline robot_model::JointPositions side_reach_pose() {
  return {{"a1", -0.6}, {"a2", 1.3}, {"a3", -0.4}, {"a4", 1.2}, {"a5", 0.6}, {"a6", 1.0}, {"a7", -0.4}};
}

}  // namespace tofguard::estimator::test
