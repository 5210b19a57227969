#include "tofguard/renderer/rendered_kinematics.hpp"

#include <cmath>

#include <map>

#include "tofguard/common/demand.hpp"
#include "tofguard/common/depth_frame.hpp"

namespace tofguard::renderer {

std::optional<Eigen::Isometry3d> world_from_optical(const robot_model::KinematicTree& tree,
                                                    const robot_model::LinkPoses& link_poses,
                                                    const CameraPose& camera_pose, std::string* why) {
  const auto refuse = [&](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return std::nullopt;
  };
  if (!link_poses.usable) return refuse(link_poses.unusable_reason);
  const int frame = tree.find_link(camera_pose.frame_id);
  if (frame < 0 || static_cast<size_t>(frame) >= link_poses.world_from_link.size()) {
    return refuse("camera pose frame '" + camera_pose.frame_id + "' is not a link of the model");
  }
  // Normalising a rotation far from unit would hide a fault upstream.
  if (const auto v = camera_pose.check(kWireQuaternionTolerance)) return refuse("camera pose: " + v->line());
  return link_poses.world_from_link[frame] * camera_pose.frame_from_optical();
}

RenderedKinematics rendered_kinematics(const robot_model::KinematicTree& tree,
                                       const robot_model::LinkPoses& link_poses,
                                       const Eigen::Isometry3d& world_from_optical) {
  TOFGUARD_DEMAND(link_poses.usable && link_poses.world_from_link.size() == tree.links.size(),
                  "rendered_kinematics: link poses do not match the tree");
  RenderedKinematics k;
  k.joint_names = tree.actuated_joint_names;
  std::map<std::string, int> actuated;
  for (size_t j = 0; j < tree.actuated_joint_names.size(); ++j) {
    actuated[tree.actuated_joint_names[j]] = static_cast<int>(j);
  }
  const Eigen::Isometry3d optical_from_world = world_from_optical.inverse();
  // URDF joint index -> axis index.
  std::vector<int> axis_of_joint(tree.joints.size(), -1);
  std::map<std::string, int> joint_index;
  for (size_t j = 0; j < tree.joints.size(); ++j) joint_index[tree.joints[j].name] = static_cast<int>(j);
  for (const std::string& name : tree.movable_joint_names) {
    const auto found = joint_index.find(name);
    TOFGUARD_DEMAND(found != joint_index.end(), "movable joint '" + name + "' is not a joint of the tree");
    const robot_model::Joint& joint = tree.joints[found->second];
    RenderedAxis axis;
    axis.urdf_joint = name;
    axis.prismatic = joint.type == robot_model::JointType::kPrismatic;
    // A mimic joint follows its leader (which may itself mimic another).
    int leader = found->second;
    double multiplier = 1;
    for (size_t hops = 0; tree.joints[leader].mimic_joint >= 0 && hops <= tree.joints.size(); ++hops) {
      multiplier *= tree.joints[leader].mimic_multiplier;
      leader = tree.joints[leader].mimic_joint;
    }
    const auto driver = actuated.find(tree.joints[leader].name);
    TOFGUARD_DEMAND(driver != actuated.end(), "joint '" + name + "' is driven by no actuated joint");
    axis.joint = driver->second;
    axis.multiplier = multiplier;
    const Eigen::Isometry3d optical_from_joint =
        optical_from_world * link_poses.world_from_link[joint.parent_link] * joint.parent_from_joint;
    axis.origin_m = optical_from_joint.translation();
    axis.direction = (optical_from_joint.linear() * joint.axis).normalized();
    axis_of_joint[found->second] = static_cast<int>(k.axes.size());
    k.axes.push_back(axis);
  }
  // The nearest moving axis at or above a link: its parent joint's axis
  // when that moves, else its parent link's.
  const auto axis_above_link = [&](int link) {
    for (size_t hops = 0; link >= 0 && hops <= tree.links.size(); ++hops) {
      const int j = tree.links[link].parent_joint;
      if (j < 0) return -1;
      if (axis_of_joint[j] >= 0) return axis_of_joint[j];
      link = tree.joints[j].parent_link;
    }
    return -1;
  };
  for (size_t j = 0; j < tree.joints.size(); ++j) {
    if (axis_of_joint[j] >= 0) k.axes[axis_of_joint[j]].parent = axis_above_link(tree.joints[j].parent_link);
  }
  k.link_axis.resize(tree.num_robot_links);
  for (int link = 0; link < tree.num_robot_links; ++link) k.link_axis[link] = axis_above_link(link);
  return k;
}

std::optional<RenderedKinematics> rendered_kinematics(const robot_model::KinematicTree& tree,
                                                      const robot_model::JointPositions& joints,
                                                      const CameraPose& camera_pose, std::string* why) {
  const robot_model::LinkPoses poses = robot_model::forward_kinematics(tree, joints);
  const auto pose = world_from_optical(tree, poses, camera_pose, why);
  if (!pose) return std::nullopt;
  return rendered_kinematics(tree, poses, *pose);
}

std::optional<RenderedKinematics> rendered_kinematics(const robot_model::KinematicTree& tree,
                                                      const RenderResult& result) {
  if (!result.usable || result.world_from_link.size() != tree.links.size()) return std::nullopt;
  robot_model::LinkPoses poses;
  poses.usable = true;
  poses.world_from_link = result.world_from_link;
  return rendered_kinematics(tree, poses, result.world_from_optical);
}

void set_rendered_kinematics(const RenderedKinematics& k, link_labels_t* labels) {
  TOFGUARD_DEMAND(k.link_axis.size() == static_cast<size_t>(labels->num_robot_links),
                  "rendered kinematics for " + std::to_string(k.link_axis.size()) +
                      " robot links, labels have " + std::to_string(labels->num_robot_links));
  labels->num_joints = static_cast<int32_t>(k.joint_names.size());
  labels->joint_name = k.joint_names;
  const auto n = static_cast<int32_t>(k.axes.size());
  labels->num_axes = n;
  labels->axis_joint.resize(n);
  labels->axis_multiplier.resize(n);
  labels->axis_prismatic.resize(n);
  // [num_axes][3]: a vector of 3-vectors in LCM's C++.
  labels->axis_origin_m.assign(n, std::vector<double>(3, 0.0));
  labels->axis_direction.assign(n, std::vector<double>(3, 0.0));
  labels->axis_parent.resize(n);
  for (int32_t m = 0; m < n; ++m) {
    const RenderedAxis& a = k.axes[m];
    labels->axis_joint[m] = a.joint;
    labels->axis_multiplier[m] = a.multiplier;
    labels->axis_prismatic[m] = a.prismatic;
    for (int c = 0; c < 3; ++c) {
      labels->axis_origin_m[m][c] = a.origin_m[c];
      labels->axis_direction[m][c] = a.direction[c];
    }
    labels->axis_parent[m] = a.parent;
  }
  if (n == 0) {
    labels->num_link_axes = 0;
    labels->link_axis.clear();
  } else {
    labels->num_link_axes = static_cast<int32_t>(k.link_axis.size());
    labels->link_axis = k.link_axis;
  }
}

void set_rendered_optical_pose(const Eigen::Isometry3d& world_from_optical, link_labels_t* labels) {
  const Eigen::Matrix<double, 3, 4> m = world_from_optical.matrix().topRows<3>();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) labels->world_from_optical[4 * r + c] = m(r, c);
  }
  labels->optical_pose_given = true;
}

RenderedArmCover rendered_arm_cover(const robot_model::ArmSpheres& cover,
                                    const robot_model::LinkPoses& link_poses,
                                    const Eigen::Isometry3d& world_from_optical,
                                    const robot_model::OccupantModel* occupant) {
  const robot_model::PlacedArmSpheres placed = robot_model::place_arm_spheres(cover, link_poses);
  const Eigen::Isometry3d optical_from_world = world_from_optical.inverse();
  RenderedArmCover out;
  out.max_radius_m = cover.max_radius_m;
  out.spheres.resize(placed.size());
  for (size_t k = 0; k < placed.size(); ++k) {
    out.spheres[k].link = cover.spheres[k].link_index;
    out.spheres[k].center_m = optical_from_world * placed[k].center_world_m;
    out.spheres[k].radius_m = placed[k].radius_m;
  }
  if (occupant != nullptr)
    out.body_region_separations_m = robot_model::body_region_separations_m(placed, *occupant);
  return out;
}

void set_rendered_arm_cover(const RenderedArmCover& cover, link_labels_t* labels) {
  const auto n = static_cast<int32_t>(cover.spheres.size());
  // Float centres are off by < 1e-6 m (at most tens of metres away): each
  // radius grows by kFloatMarginM so that the sphere on the wire still
  // holds its triangles, and the maximum by twice that (float rounding of
  // the grown radius).
  constexpr double kFloatMarginM = 1e-6;
  labels->arm_cover_max_radius_m = cover.max_radius_m + 2 * kFloatMarginM;
  labels->num_arm_spheres = n;
  labels->arm_sphere_link.resize(n);
  // [num_arm_spheres][3]: a vector of 3-vectors in LCM's C++.
  labels->arm_sphere_center_m.assign(n, std::vector<float>(3, 0.0f));
  labels->arm_sphere_radius_m.resize(n);
  for (int32_t k = 0; k < n; ++k) {
    const RenderedArmCover::Sphere& sphere = cover.spheres[k];
    labels->arm_sphere_link[k] = static_cast<int16_t>(sphere.link);
    for (int c = 0; c < 3; ++c) labels->arm_sphere_center_m[k][c] = static_cast<float>(sphere.center_m[c]);
    labels->arm_sphere_radius_m[k] = static_cast<float>(sphere.radius_m + kFloatMarginM);
  }
  labels->num_body_regions = static_cast<int32_t>(cover.body_region_separations_m.size());
  labels->body_region.clear();
  labels->body_region_separation_m.clear();
  for (const auto& [region, separation_m] : cover.body_region_separations_m) {
    labels->body_region.push_back(body_region_name(region));
    // Rounded down to a float: never more than the separation computed.
    float on_wire = static_cast<float>(separation_m);
    if (on_wire > separation_m) on_wire = std::nextafter(on_wire, 0.0f);
    labels->body_region_separation_m.push_back(on_wire);
  }
}

link_labels_t make_rendered_link_labels(const depth_image_t& frame, const RenderResult& result,
                                        const robot_model::KinematicTree& tree,
                                        const robot_model::ArmSpheres& cover) {
  if (!result.usable) {
    return make_unusable_link_labels(frame, tree.num_robot_links, tree.link_names(), result.unusable_reason);
  }
  link_labels_t labels = make_link_labels(frame, tree.num_robot_links, tree.link_names(), result.labels);
  if (const auto k = rendered_kinematics(tree, result)) set_rendered_kinematics(*k, &labels);
  if (result.world_from_link.size() == tree.links.size()) {
    robot_model::LinkPoses poses;
    poses.usable = true;
    poses.world_from_link = result.world_from_link;
    set_rendered_arm_cover(rendered_arm_cover(cover, poses, result.world_from_optical), &labels);
  }
  return labels;
}

}  // namespace tofguard::renderer
