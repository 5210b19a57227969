// renderer/rendered_kinematics.hpp: the axes in the optical frame move
// points of the links they carry as forward kinematics does.
#include <gtest/gtest.h>

#include "estimator_test_support.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"

namespace tofguard::renderer {
namespace {

TEST(RenderedKinematics, AxesMoveLinkPointsAsForwardKinematicsDoes) {
  const deployment::Config config = estimator::test::sim_config();
  const robot_model::KinematicTree tree = robot_model::load_kinematic_tree(config.robot.urdf_path);
  const robot_model::JointPositions q = estimator::test::side_reach_pose();
  Eigen::Isometry3d world_from_optical = Eigen::Isometry3d::Identity();
  world_from_optical.translation() = Eigen::Vector3d(1.5, -0.5, 1.2);
  world_from_optical.linear() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const robot_model::LinkPoses poses = robot_model::forward_kinematics(tree, q);
  const RenderedKinematics k = rendered_kinematics(tree, poses, world_from_optical);
  ASSERT_EQ(k.joint_names, tree.actuated_joint_names);
  ASSERT_EQ(k.axes.size(), tree.movable_joint_names.size());
  ASSERT_EQ(k.link_axis.size(), static_cast<size_t>(tree.num_robot_links));
  const Eigen::Isometry3d optical_from_world = world_from_optical.inverse();
  const Eigen::Vector3d point_in_link(0.05, -0.03, 0.08);
  constexpr double kEps = 1e-6;
  for (size_t m = 0; m < k.axes.size(); ++m) {
    const RenderedAxis& a = k.axes[m];
    EXPECT_NEAR(a.direction.norm(), 1.0, 1e-12);
    EXPECT_LT(a.parent, static_cast<int>(m));
    const std::string child = tree.child_link(a.urdf_joint);
    const int link = tree.find_link(child);
    ASSERT_GE(link, 0);
    EXPECT_EQ(k.link_axis[link], static_cast<int>(m)) << child;
    // Moving the driving joint by eps moves a point of the child link by
    // multiplier * eps * (direction x (p - origin)) in the optical frame.
    robot_model::JointPositions moved = q;
    moved[k.joint_names[a.joint]] += kEps;
    const robot_model::LinkPoses after = robot_model::forward_kinematics(tree, moved);
    const Eigen::Vector3d p0 = optical_from_world * poses.world_from_link[link] * point_in_link;
    const Eigen::Vector3d p1 = optical_from_world * after.world_from_link[link] * point_in_link;
    // Every axis of this joint at or above the link contributes.
    Eigen::Vector3d predicted = Eigen::Vector3d::Zero();
    for (int n = static_cast<int>(m); n >= 0; n = k.axes[n].parent) {
      const RenderedAxis& b = k.axes[n];
      if (b.joint != a.joint) continue;
      predicted += b.multiplier * kEps * (b.prismatic ? b.direction : b.direction.cross(p0 - b.origin_m));
    }
    EXPECT_LT((p1 - p0 - predicted).norm(), 1e-9) << a.urdf_joint;
  }
  EXPECT_EQ(k.link_axis[0], -1) << "the root is fixed";
}

TEST(RenderedKinematics, WrittenIntoLinkLabelsPassTheWireChecks) {
  const deployment::Config config = estimator::test::sim_config();
  const robot_model::KinematicTree tree = robot_model::load_kinematic_tree(config.robot.urdf_path);
  const auto k = rendered_kinematics(tree, estimator::test::reach_pose(), config.camera.pose);
  ASSERT_TRUE(k.has_value());
  const depth_image_t frame =
      make_depth_image("cam", Intrinsics{4, 3, 10, 10, 2, 1}, 1, 1, true, std::vector<float>(12, 1.0f));
  link_labels_t labels = make_link_labels(frame, tree.num_robot_links, tree.link_names(),
                                          std::vector<int16_t>(12, kLabelNothing));
  set_rendered_kinematics(*k, &labels);
  EXPECT_EQ(labels.num_axes, static_cast<int>(tree.movable_joint_names.size()));
  EXPECT_EQ(check_link_labels(labels), "");
  labels.axis_direction[1][0] += 1e-3;
  EXPECT_NE(check_link_labels(labels).find("axis_direction[1]"), std::string::npos)
      << check_link_labels(labels);
  // A joint missing from the state: no kinematics.
  robot_model::JointPositions missing = estimator::test::reach_pose();
  missing.erase(missing.begin());
  std::string why;
  EXPECT_FALSE(rendered_kinematics(tree, missing, config.camera.pose, &why).has_value());
  EXPECT_FALSE(why.empty());
}

}  // namespace
}  // namespace tofguard::renderer
