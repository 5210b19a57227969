#include "tofguard/estimator/estimate_message.hpp"

#include <algorithm>
#include <limits>

namespace tofguard::estimator {

namespace {

void set_pose(const Eigen::Isometry3d& pose, double translation[3], double rotation[4]) {
  const Eigen::Quaterniond q(pose.linear());
  for (int i = 0; i < 3; ++i) translation[i] = pose.translation()[i];
  rotation[0] = q.w();
  rotation[1] = q.x();
  rotation[2] = q.y();
  rotation[3] = q.z();
}

int32_t clamp_int32(int64_t v) {
  return static_cast<int32_t>(std::clamp<int64_t>(v, 0, std::numeric_limits<int32_t>::max()));
}

motion_estimate_t base_message(const EstimateContext& context) {
  motion_estimate_t m;
  m.utime = context.utime;
  m.seq = context.seq;
  m.camera_id = context.camera_id;
  m.trigger = context.trigger;
  m.usable = false;
  m.converged = false;
  m.iterations = 0;
  m.num_frames = 0;
  m.num_joints = 0;
  set_pose(Eigen::Isometry3d::Identity(), m.correction_translation, m.correction_rotation);
  m.correction_translation_sigma_m = 0;
  m.correction_rotation_sigma_rad = 0;
  m.frame_id = context.frame_id;
  set_pose(context.frame_from_optical, m.estimated_translation, m.estimated_rotation);
  m.num_points = 0;
  m.num_inliers = 0;
  m.residual_before_mm = 0;
  m.residual_after_mm = 0;
  m.compute_us = 0;
  return m;
}

}  // namespace

motion_estimate_t unusable_message(const EstimateContext& context, const std::string& why) {
  motion_estimate_t m = base_message(context);
  m.unusable_reason = why;
  // Every joint as reported, none observable.
  m.num_joints = static_cast<int32_t>(context.joint_names.size());
  m.joint_name = context.joint_names;
  for (size_t k = 0; k < context.joint_names.size(); ++k) {
    const double reported = k < context.reported_positions.size() ? context.reported_positions[k] : 0.0;
    m.reported_position.push_back(reported);
    m.estimated_position.push_back(reported);
    m.position_sigma.push_back(kUnobservableSigma);
    m.observable.push_back(false);
  }
  return m;
}

motion_estimate_t to_message(const EstimateResult& result, const EstimateContext& context) {
  if (!result.usable) {
    motion_estimate_t m = unusable_message(context, result.unusable_reason);
    m.compute_us = clamp_int32(result.compute_us);
    return m;
  }
  motion_estimate_t m = base_message(context);
  m.usable = true;
  m.converged = result.converged;
  m.iterations = result.iterations;
  m.num_frames = result.num_frames;
  m.num_joints = static_cast<int32_t>(result.joints.size());
  for (const JointEstimate& j : result.joints) {
    m.joint_name.push_back(j.name);
    m.reported_position.push_back(j.reported);
    m.estimated_position.push_back(j.estimated);
    m.position_sigma.push_back(j.sigma);
    m.observable.push_back(j.observable);
  }
  set_pose(result.correction, m.correction_translation, m.correction_rotation);
  m.correction_translation_sigma_m = result.correction_translation_sigma_m;
  m.correction_rotation_sigma_rad = result.correction_rotation_sigma_rad;
  set_pose(context.frame_from_optical * result.correction, m.estimated_translation, m.estimated_rotation);
  m.num_points = result.num_points;
  m.num_inliers = result.num_inliers;
  m.residual_before_mm = result.residual_before_m * 1000;
  m.residual_after_mm = result.residual_after_m * 1000;
  m.compute_us = clamp_int32(result.compute_us);
  return m;
}

}  // namespace tofguard::estimator
