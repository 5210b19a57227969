#pragma once
// An EstimateResult as motion_estimate_t (lcmtypes/motion_estimate_t.lcm
// fixes the semantics).
#include <string>

#include <Eigen/Geometry>

#include "tofguard/estimator/motion_estimator.hpp"
#include "tofguard/motion_estimate_t.hpp"

namespace tofguard::estimator {

// What the message says about the frame, apart from the result.
struct EstimateContext {
  int64_t utime = 0;
  int64_t seq = 0;
  std::string camera_id;
  int8_t trigger = motion_estimate_t::TRIGGER_PERIODIC;
  // The reported camera pose's frame and the optical frame's reported pose
  // in it (p_frame = frame_from_optical * p_optical).
  std::string frame_id;
  Eigen::Isometry3d frame_from_optical = Eigen::Isometry3d::Identity();
  // The actuated joints (URDF order) and their reported positions, for a
  // result that is unusable (its joints are then empty).
  std::vector<std::string> joint_names;
  std::vector<double> reported_positions;
};

motion_estimate_t to_message(const EstimateResult& result, const EstimateContext& context);

// An unusable estimate saying why (no joint state for the frame, ...).
motion_estimate_t unusable_message(const EstimateContext& context, const std::string& why);

}  // namespace tofguard::estimator
