// The kinematic tree: the joint sets, limits and geometry the URDF states,
// the tree queries the risk rules ask (distal links, the nearest movable
// joint above), environments beside the robot, and one-line load errors.
#include <gtest/gtest.h>

#include "model_test_util.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"

namespace tofguard::robot_model::test {
namespace {

using tofguard::test::source_dir;
using tofguard::test::write_test_file;

const KinematicTree& friend_arm() {
  static const KinematicTree tree = load_kinematic_tree(source_dir() + "/config/models/friend_arm.urdf");
  return tree;
}

TEST(KinematicTree, FriendArmJointsAndDistalLinks) {
  const KinematicTree& tree = friend_arm();
  const std::vector<std::string> arm_joints{"a1", "a2", "a3", "a4", "a5", "a6", "a7"};
  EXPECT_EQ(tree.movable_joint_names, arm_joints);
  EXPECT_EQ(tree.actuated_joint_names, arm_joints);
  EXPECT_TRUE(tree.prismatic_joint_names.empty());
  EXPECT_TRUE(tree.is_movable_joint("a3"));
  EXPECT_FALSE(tree.is_movable_joint("gripper_mount"));
  EXPECT_EQ(tree.nearest_movable_joint_above("link4"), "a4");
  // The gripper hangs on a fixed joint below link7.
  EXPECT_EQ(tree.nearest_movable_joint_above("gripper"), "a7");
  EXPECT_EQ(tree.nearest_movable_joint_above("base_link"), "");
  EXPECT_EQ(tree.lowest_common_ancestor({"gripper", "link5", "link6"}), "link5");
  EXPECT_EQ(tree.lowest_common_ancestor({"link7"}), "link7");
  EXPECT_TRUE(tree.is_descendant_or_self("gripper", "link2"));
  EXPECT_FALSE(tree.is_descendant_or_self("link1", "link2"));
  EXPECT_EQ(tree.chain_from_root("link2"),
            (std::vector<std::string>{"world", "base_link", "link1", "link2"}));
  EXPECT_EQ(tree.child_link("a3"), "link3");
  EXPECT_EQ(tree.child_link("no_such_joint"), "");
}

TEST(KinematicTree, FriendArmLimitsAndGeometryAsStated) {
  const KinematicTree& tree = friend_arm();
  const Joint& a2 = tree.joints[tree.links[tree.find_link("link2")].parent_joint];
  EXPECT_EQ(a2.name, "a2");
  EXPECT_TRUE(a2.limits.has_position_limits);
  EXPECT_DOUBLE_EQ(a2.limits.lower, -2.0);
  EXPECT_DOUBLE_EQ(a2.limits.upper, 2.0);
  EXPECT_DOUBLE_EQ(a2.limits.velocity, 1.5);
  EXPECT_DOUBLE_EQ(a2.limits.effort, 100);
  EXPECT_FALSE(tree.links[tree.find_link("link2")].visuals.empty());
}

// base -slide prismatic-> carriage -spin continuous-> wheel
//      -left revolute-> finger_left, -right revolute mimics left-> finger_right
constexpr const char* kBranched = R"(<?xml version="1.0"?>
<robot name="branched">
  <link name="base"/>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="carriage"/><axis xyz="1 0 0"/>
    <limit lower="-0.5" upper="0.5" effort="10" velocity="0.2"/></joint>
  <link name="carriage"><visual><geometry><box size="0.1 0.2 0.3"/></geometry></visual></link>
  <joint name="spin" type="continuous"><parent link="carriage"/><child link="wheel"/><axis xyz="0 0 1"/></joint>
  <link name="wheel"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>
  <joint name="left" type="revolute"><parent link="carriage"/><child link="finger_left"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="1" effort="1" velocity="1"/></joint>
  <link name="finger_left"/>
  <joint name="right" type="revolute"><parent link="carriage"/><child link="finger_right"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="0" effort="1" velocity="1"/><mimic joint="left" multiplier="-1"/></joint>
  <link name="finger_right"/>
</robot>
)";

constexpr const char* kTable = R"(<?xml version="1.0"?>
<robot name="table">
  <link name="floor"/>
  <joint name="legs" type="fixed"><parent link="floor"/><child link="top"/><origin xyz="1 0 0.7"/></joint>
  <link name="top"><visual><geometry><box size="1 1 0.05"/></geometry></visual></link>
</robot>
)";

TEST(KinematicTree, BranchesMimicsPrismaticJointsAndAnEnvironment) {
  const KinematicTree tree = load_kinematic_tree(write_test_file("branched.urdf", kBranched),
                                                 {write_test_file("table.urdf", kTable)});
  // Siblings in the order of their names, mimic joints move but are not
  // actuated, environment joints are fixed.
  EXPECT_EQ(tree.movable_joint_names, (std::vector<std::string>{"slide", "left", "right", "spin"}));
  EXPECT_EQ(tree.actuated_joint_names, (std::vector<std::string>{"slide", "left", "spin"}));
  EXPECT_EQ(tree.prismatic_joint_names, (std::set<std::string>{"slide"}));
  EXPECT_TRUE(tree.is_prismatic_joint("slide"));
  EXPECT_FALSE(tree.is_prismatic_joint("spin"));
  EXPECT_EQ(tree.num_robot_links, 5);
  EXPECT_EQ(tree.link_names(), (std::vector<std::string>{"base", "carriage", "finger_left", "finger_right",
                                                         "wheel", "floor", "top"}));
  EXPECT_TRUE(tree.is_robot_link("wheel"));
  EXPECT_FALSE(tree.is_robot_link("top"));
  EXPECT_FALSE(tree.is_robot_link("nowhere"));
  EXPECT_TRUE(tree.links[tree.find_link("top")].is_environment);

  const Joint& spin = tree.joints[tree.links[tree.find_link("wheel")].parent_joint];
  EXPECT_FALSE(spin.limits.has_position_limits);
  const Joint& right = tree.joints[tree.links[tree.find_link("finger_right")].parent_joint];
  ASSERT_GE(right.mimic_joint, 0);
  EXPECT_EQ(tree.joints[right.mimic_joint].name, "left");
  EXPECT_DOUBLE_EQ(right.mimic_multiplier, -1);

  EXPECT_EQ(tree.lowest_common_ancestor({"finger_left", "finger_right", "wheel"}), "carriage");
  EXPECT_EQ(tree.nearest_movable_joint_above("finger_right"), "right");
  EXPECT_EQ(tree.nearest_movable_joint_above("carriage"), "slide");
  // The environment is a tree of its own, fixed to the world.
  EXPECT_EQ(tree.lowest_common_ancestor({"top", "wheel"}), "");
  EXPECT_EQ(tree.nearest_movable_joint_above("top"), "");
  EXPECT_EQ(tree.chain_from_root("top"), (std::vector<std::string>{"floor", "top"}));

  // Geometry as stated, both sources.
  const Link& carriage = tree.links[tree.find_link("carriage")];
  ASSERT_EQ(carriage.visuals.size(), 1u);
  EXPECT_EQ(carriage.visuals[0].kind, GeometryElement::Kind::kBox);
  EXPECT_TRUE(carriage.visuals[0].box_size_m.isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_TRUE(carriage.collisions.empty());
  const Link& wheel = tree.links[tree.find_link("wheel")];
  ASSERT_EQ(wheel.collisions.size(), 1u);
  EXPECT_EQ(wheel.collisions[0].kind, GeometryElement::Kind::kCylinder);
  EXPECT_DOUBLE_EQ(wheel.collisions[0].radius_m, 0.05);
  EXPECT_DOUBLE_EQ(wheel.collisions[0].length_m, 0.02);
}

TEST(KinematicTreeErrors, OneLineNamingTheFileAndJoint) {
  const std::string malformed =
      write_test_file("tree_malformed.urdf", "<robot name='x'><link name='a'/><oops/>");
  try {
    load_kinematic_tree(malformed);
    FAIL() << "expected ModelError";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find(malformed + ": malformed URDF"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_kinematic_tree(source_dir() + "/no/such/file.urdf"), ModelError);
  const std::string floating = write_test_file(
      "tree_floating.urdf",
      "<robot name='f'><link name='a'/><joint name='free' type='floating'><parent link='a'/><child link='b'/>"
      "</joint><link name='b'/></robot>");
  try {
    load_kinematic_tree(floating);
    FAIL() << "expected ModelError";
  } catch (const ModelError& e) {
    EXPECT_EQ(std::string(e.what()),
              floating +
                  ": joint 'free': type not supported (fixed, revolute, continuous and "
                  "prismatic are)");
  }
}

}  // namespace
}  // namespace tofguard::robot_model::test
