// Forward kinematics of a small chain with revolute, prismatic, fixed,
// mimic and continuous joints against transforms written out by hand.
#include <gtest/gtest.h>

#include "model_test_util.hpp"
#include "tofguard/robot_model/kinematics.hpp"

namespace tofguard::robot_model::test {
namespace {

using tofguard::test::pose;
using tofguard::test::write_test_file;

// base -j1 revolute z-> l1 -j2 prismatic x-> l2 -j3 fixed-> l3
//   -j4 revolute y, mimics j1 (x2, +0.1)-> l4 -j5 continuous (0, 0.6, 0.8)-> l5
constexpr const char* kChain = R"(<?xml version="1.0"?>
<robot name="chain">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.3 -0.2 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <link name="l1"/>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.4" rpy="0 0.5 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="l2"/>
  <joint name="j3" type="fixed"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.05 0 0" rpy="0.1 0.2 0.3"/></joint>
  <link name="l3"/>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/>
    <origin xyz="0 0.1 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
    <mimic joint="j1" multiplier="2" offset="0.1"/></joint>
  <link name="l4"/>
  <joint name="j5" type="continuous"><parent link="l4"/><child link="l5"/>
    <origin xyz="0.2 0 0.1" rpy="-0.4 0 0.2"/><axis xyz="0 0.6 0.8"/></joint>
  <link name="l5"/>
</robot>
)";

Eigen::Isometry3d rotation_about(const Eigen::Vector3d& unit_axis, double angle) {
  // Rodrigues' formula, written out.
  Eigen::Matrix3d k;
  k << 0, -unit_axis.z(), unit_axis.y(), unit_axis.z(), 0, -unit_axis.x(), -unit_axis.y(), unit_axis.x(), 0;
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Matrix3d::Identity() + std::sin(angle) * k + (1 - std::cos(angle)) * k * k;
  return t;
}

Eigen::Isometry3d translation(const Eigen::Vector3d& v) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = v;
  return t;
}

class Kinematics : public ::testing::Test {
 protected:
  void SetUp() override { tree = load_kinematic_tree(write_test_file("chain.urdf", kChain)); }
  const Eigen::Isometry3d& pose_of(const LinkPoses& poses, const std::string& link) {
    const int index = tree.find_link(link);
    EXPECT_GE(index, 0) << link;
    return poses.world_from_link.at(index);
  }
  KinematicTree tree;
};

TEST_F(Kinematics, ChainMatchesHandComputedTransforms) {
  const double q1 = 0.7, q2 = 0.25, q5 = -1.1;
  const LinkPoses poses = forward_kinematics(tree, {{"j1", q1}, {"j2", q2}, {"j5", q5}, {"unrelated", 9.0}});
  ASSERT_TRUE(poses.usable) << poses.unusable_reason;
  ASSERT_EQ(tree.actuated_joint_names, (std::vector<std::string>{"j1", "j2", "j5"}));

  const Eigen::Isometry3d l1 = pose({0.1, 0.2, 0.3}, {0.3, -0.2, 0.5}) * rotation_about({0, 0, 1}, q1);
  const Eigen::Isometry3d l2 = l1 * pose({0, 0, 0.4}, {0, 0.5, 0}) * translation({q2, 0, 0});
  const Eigen::Isometry3d l3 = l2 * pose({0.05, 0, 0}, {0.1, 0.2, 0.3});
  const Eigen::Isometry3d l4 = l3 * pose({0, 0.1, 0}, {0, 0, 0}) * rotation_about({0, 1, 0}, 2 * q1 + 0.1);
  const Eigen::Isometry3d l5 = l4 * pose({0.2, 0, 0.1}, {-0.4, 0, 0.2}) * rotation_about({0, 0.6, 0.8}, q5);

  EXPECT_TRUE(pose_of(poses, "base").isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  EXPECT_TRUE(pose_of(poses, "l1").isApprox(l1, 1e-12)) << pose_of(poses, "l1").matrix() << "\n"
                                                        << l1.matrix();
  EXPECT_TRUE(pose_of(poses, "l2").isApprox(l2, 1e-12));
  EXPECT_TRUE(pose_of(poses, "l3").isApprox(l3, 1e-12));
  EXPECT_TRUE(pose_of(poses, "l4").isApprox(l4, 1e-12));
  EXPECT_TRUE(pose_of(poses, "l5").isApprox(l5, 1e-12)) << pose_of(poses, "l5").matrix() << "\n"
                                                        << l5.matrix();
  // A number to read: where l5's origin is.
  EXPECT_NEAR((pose_of(poses, "l5").translation() - l5.translation()).norm(), 0, 1e-12);
}

TEST_F(Kinematics, WrongRpyOrderOrAxisWouldBeDetected) {
  // The hand-written transforms above differ measurably from the usual
  // mistakes, so the test above would catch them.
  const LinkPoses poses = forward_kinematics(tree, {{"j1", 0.7}, {"j2", 0.25}, {"j5", -1.1}});
  ASSERT_TRUE(poses.usable);
  Eigen::Isometry3d xyz_order = Eigen::Isometry3d::Identity();
  xyz_order.translation() = Eigen::Vector3d(0.1, 0.2, 0.3);
  xyz_order.linear() =
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  const Eigen::Isometry3d wrong_l1 = xyz_order * rotation_about({0, 0, 1}, 0.7);
  EXPECT_GT((pose_of(poses, "l1").linear() - wrong_l1.linear()).norm(), 0.05);
  const Eigen::Isometry3d right_l1 = pose({0.1, 0.2, 0.3}, {0.3, -0.2, 0.5});
  const Eigen::Isometry3d wrong_axis = right_l1 * rotation_about({0, 1, 0}, 0.7);
  EXPECT_GT((pose_of(poses, "l1").linear() - wrong_axis.linear()).norm(), 0.5);
}

TEST_F(Kinematics, MissingJointMakesTheResultUnusableNamingTheJoint) {
  const LinkPoses poses = forward_kinematics(tree, {{"j1", 0.7}, {"j5", 0.0}});
  EXPECT_FALSE(poses.usable);
  EXPECT_EQ(poses.unusable_reason, "joint 'j2' missing from the joint state");
  EXPECT_TRUE(poses.world_from_link.empty());
}

TEST_F(Kinematics, NonFiniteJointValueIsUnusable) {
  const LinkPoses poses = forward_kinematics(tree, {{"j1", 0.7}, {"j2", std::nan("")}, {"j5", 0.0}});
  EXPECT_FALSE(poses.usable);
  EXPECT_EQ(poses.unusable_reason, "joint 'j2' is not a finite number");
}

TEST_F(Kinematics, MimicJointIgnoresAValueOfItsOwn) {
  // The mimic follows j1 even if the joint state reports something else for it.
  const LinkPoses a = forward_kinematics(tree, {{"j1", 0.7}, {"j2", 0.0}, {"j5", 0.0}});
  const LinkPoses b = forward_kinematics(tree, {{"j1", 0.7}, {"j2", 0.0}, {"j5", 0.0}, {"j4", 2.0}});
  ASSERT_TRUE(a.usable && b.usable);
  EXPECT_TRUE(pose_of(a, "l4").isApprox(pose_of(b, "l4"), 1e-15));
}

}  // namespace
}  // namespace tofguard::robot_model::test
