#include "tofguard/robot_model/kinematics.hpp"

#include <cmath>

namespace tofguard::robot_model {

Eigen::Isometry3d joint_motion(const Joint& joint, double value) {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  switch (joint.type) {
    case JointType::kRevolute:
    case JointType::kContinuous:
      motion.linear() = Eigen::AngleAxisd(value, joint.axis).toRotationMatrix();
      break;
    case JointType::kPrismatic:
      motion.translation() = value * joint.axis;
      break;
    case JointType::kFixed:
      break;
  }
  return motion;
}

LinkPoses forward_kinematics(const KinematicTree& tree, const JointPositions& joints) {
  LinkPoses result;
  // Joint values first, so that a missing joint is reported by name before
  // anything is computed.
  std::vector<double> value(tree.joints.size(), 0.0);
  for (size_t j = 0; j < tree.joints.size(); ++j) {
    const Joint& joint = tree.joints[j];
    if (joint.type == JointType::kFixed || joint.mimic_joint >= 0) continue;
    const auto found = joints.find(joint.name);
    if (found == joints.end()) {
      result.unusable_reason = "joint '" + joint.name + "' missing from the joint state";
      return result;
    }
    if (!std::isfinite(found->second)) {
      result.unusable_reason = "joint '" + joint.name + "' is not a finite number";
      return result;
    }
    value[j] = found->second;
  }
  // Mimic chains end at an actuated joint (checked at load).
  for (size_t j = 0; j < tree.joints.size(); ++j) {
    if (tree.joints[j].mimic_joint < 0) continue;
    double multiplier = 1, offset = 0;
    int at = static_cast<int>(j);
    while (tree.joints[at].mimic_joint >= 0) {
      offset = multiplier * tree.joints[at].mimic_offset + offset;
      multiplier *= tree.joints[at].mimic_multiplier;
      at = tree.joints[at].mimic_joint;
    }
    value[j] = multiplier * value[at] + offset;
  }
  result.world_from_link.assign(tree.links.size(), Eigen::Isometry3d::Identity());
  for (size_t j = 0; j < tree.joints.size(); ++j) {
    const Joint& joint = tree.joints[j];
    result.world_from_link[joint.child_link] =
        result.world_from_link[joint.parent_link] * joint.parent_from_joint * joint_motion(joint, value[j]);
  }
  result.usable = true;
  return result;
}

}  // namespace tofguard::robot_model
