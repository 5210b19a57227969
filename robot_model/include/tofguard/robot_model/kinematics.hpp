#pragma once
// Forward kinematics of a KinematicTree with Eigen: where every link is in the
// world frame (the robot's root link) for given joint values.
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/robot_model/kinematic_tree.hpp"

namespace tofguard::robot_model {

// Joint values matched by URDF joint name: radians for revolute and
// continuous joints, metres for prismatic joints. Names that the model does
// not have are ignored (a joint state may carry more, e.g. a gripper).
using JointPositions = std::map<std::string, double>;

struct LinkPoses {
  // False when the poses must not be used; then `unusable_reason` says why
  // in one line (e.g. "joint 'a3' missing from the joint state") and
  // world_from_link is empty.
  bool usable = false;
  std::string unusable_reason;
  // Pose of each link (KinematicTree::links order) in the world frame:
  // p_world = world_from_link[i] * p_link.
  std::vector<Eigen::Isometry3d> world_from_link;
};

// Every actuated joint must be present and finite; mimic joints follow their
// leader (value = multiplier * leader + offset) and need not be present.
// Joint limits are not applied: the renderer shows what the joint state
// reports. Never throws for a bad joint state.
LinkPoses forward_kinematics(const KinematicTree& tree, const JointPositions& joints);

// Motion of one joint at `value`: joint frame -> child link frame.
Eigen::Isometry3d joint_motion(const Joint& joint, double value);

}  // namespace tofguard::robot_model
