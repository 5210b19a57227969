// The robot's cover of spheres (arm_spheres.hpp): conservative (never
// farther than the true surface, at most 2 * max_radius_m nearer), only the
// robot's links, moving with the joints; on the default arm, the iiwa14 and
// the Kinova Gen3.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "model_test_util.hpp"
#include "tofguard/robot_model/arm_spheres.hpp"
#include "tofguard/robot_model/kinematics.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tool_support.hpp"

namespace tofguard::robot_model {
namespace {

namespace fs = std::filesystem;

// A box link 0.4 x 0.1 x 0.1 m (its centre 0.2 m along x from the joint)
// on a revolute joint about z at the base, and an environment box.
SceneModel box_arm() {
  const std::string robot = test::write_test_file("spheres_arm.urdf", R"(<robot name="a">
  <link name="base"/>
  <link name="l1"><visual><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.1 0.1"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>)");
  const std::string table = test::write_test_file("spheres_table.urdf", R"(<robot name="t">
  <link name="table"><visual><origin xyz="0 0.3 0"/><geometry><box size="0.2 0.2 0.2"/></geometry></visual></link>
</robot>)");
  return load_scene(robot, {table}, {});
}

// True distance (m) from p to the surface of the axis-aligned box [lo, hi]
// (for a point inside: to its nearest face).
double distance_to_box_surface(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                               const Eigen::Vector3d& hi) {
  const bool inside = (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  if (inside) return std::min((p - lo).minCoeff(), (hi - p).minCoeff());
  return (p - p.cwiseMax(lo).cwiseMin(hi)).norm();
}

TEST(ArmSpheres, DistancesAreNeverFartherThanTheSurfaceAndAtMostTwoRadiiNearer) {
  const SceneModel scene = box_arm();
  const ArmSpheres cover = cover_arm_with_spheres(scene, 0.02);
  ASSERT_FALSE(cover.spheres.empty());
  for (const LinkSphere& s : cover.spheres) EXPECT_LT(s.link_index, scene.num_robot_links);
  // Triangles split to edges <= 2 cm in 2 cm cells: no sphere wider than
  // a cell's diagonal plus an edge.
  EXPECT_LE(cover.max_radius_m, 0.02 * std::sqrt(3.0) + 0.02);
  const LinkPoses poses = forward_kinematics(scene, {{"j1", 0.0}});
  ASSERT_TRUE(poses.usable);
  const PlacedArmSpheres placed = place_arm_spheres(cover, poses);
  const Eigen::Vector3d lo(0, -0.05, -0.05), hi(0.4, 0.05, 0.05);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-0.6, 0.8);
  for (int i = 0; i < 2000; ++i) {
    // One draw per statement: the order of a constructor's arguments is
    // unspecified (GCC and clang differ), and the points must not.
    const double x = coordinate(random);
    const double y = coordinate(random);
    const double z = coordinate(random);
    const Eigen::Vector3d p(x, y, z);
    const double truth = distance_to_box_surface(p, lo, hi);
    const double seen = distance_to_arm_m(placed, p);
    EXPECT_LE(seen, truth + 1e-9) << p.transpose();
    EXPECT_GE(seen, truth - 2 * cover.max_radius_m - 1e-9) << p.transpose();
  }
  // Points on the surface are at distance 0; the environment's box (0.3 m
  // along y) does not count: a point on it is its distance from the arm.
  EXPECT_LE(distance_to_arm_m(placed, Eigen::Vector3d(0.4, 0, 0)), 1e-9);
  EXPECT_LE(distance_to_arm_m(placed, Eigen::Vector3d(0.2, 0.05, 0.01)), 1e-9);
  const double at_table = distance_to_arm_m(placed, Eigen::Vector3d(0, 0.2, 0));
  EXPECT_LE(at_table, 0.15 + 1e-9);
  EXPECT_GE(at_table, 0.15 - 2 * cover.max_radius_m);
}

TEST(ArmSpheres, TheCoverMovesWithTheJoints) {
  const SceneModel scene = box_arm();
  const ArmSpheres cover = cover_arm_with_spheres(scene, 0.02);
  const Eigen::Vector3d tip_when_turned(0, 0.4, 0);  // l1's far end with j1 at +90 deg
  const PlacedArmSpheres straight = place_arm_spheres(cover, forward_kinematics(scene, {{"j1", 0.0}}));
  const PlacedArmSpheres turned = place_arm_spheres(cover, forward_kinematics(scene, {{"j1", M_PI / 2}}));
  EXPECT_LE(distance_to_arm_m(turned, tip_when_turned), 1e-9);
  // Straight, the nearest arm point to (0, 0.4, 0) is (0, 0.05, 0): 0.35 m.
  const double seen = distance_to_arm_m(straight, tip_when_turned);
  EXPECT_LE(seen, 0.35 + 1e-9);
  EXPECT_GE(seen, 0.35 - 2 * cover.max_radius_m);
}

// Every corner of every robot shape lies inside the cover (distance 0) on
// the three arms, bent; the cover's size and error bound are printed.
void expect_every_corner_covered(const SceneModel& scene, const std::string& name) {
  const ArmSpheres cover = cover_arm_with_spheres(scene, 0.02);
  JointPositions q;
  for (size_t j = 0; j < scene.actuated_joint_names.size(); ++j)
    q[scene.actuated_joint_names[j]] = 0.3 * (j + 1);
  const LinkPoses poses = forward_kinematics(scene, q);
  ASSERT_TRUE(poses.usable) << poses.unusable_reason;
  const PlacedArmSpheres placed = place_arm_spheres(cover, poses);
  size_t corners = 0, triangles = 0;
  for (const Shape& shape : scene.shapes) {
    if (shape.link_index >= scene.num_robot_links) continue;
    const TriangleMesh& mesh = scene.meshes[static_cast<size_t>(shape.mesh_index)];
    triangles += mesh.num_triangles();
    // Every 7th corner keeps the brute-force check fast on 90k triangles.
    for (size_t i = 0; i < mesh.vertices.size(); i += 7) {
      const Eigen::Vector3d p =
          poses.world_from_link[static_cast<size_t>(shape.link_index)] *
          (shape.link_from_shape * shape.scale.cwiseProduct(mesh.vertices[i].cast<double>()));
      ASSERT_LE(distance_to_arm_m(placed, p), 1e-9) << name << " corner " << i;
      ++corners;
    }
  }
  EXPECT_GT(corners, 0u) << name;
  EXPECT_LE(cover.max_radius_m, 0.02 * std::sqrt(3.0) + 0.02) << name;
  std::printf("%s: %zu triangles -> %zu spheres (2 cm cells), max radius %.1f mm, %zu corners checked\n",
              name.c_str(), triangles, cover.spheres.size(), cover.max_radius_m * 1e3, corners);
}

TEST(ArmSpheres, EveryCornerOfTheDefaultArmTheIiwa14AndTheKinovaGen3IsCovered) {
  const std::string config_dir = test::source_dir() + "/config/";
  expect_every_corner_covered(load_scene(config_dir + "models/friend_arm.urdf", {}, {}), "default arm");
  if (test::shared_dir().empty())
    GTEST_SKIP() << "../shared is absent: the iiwa14 and Kinova Gen3 models are not available";
  const fs::path robots = fs::path(test::shared_dir()) / "robots";
  const fs::path iiwa = robots / "iiwa14" / "urdf" / "iiwa14_no_collision_relative.urdf";
  if (!fs::exists(iiwa)) GTEST_SKIP() << iiwa << " is absent";
  expect_every_corner_covered(load_scene(iiwa.string(), {}, {}), "iiwa14");
  const fs::path kinova = robots / "kinova_gen3" / "kortex_description" / "arms" / "gen3" / "7dof" / "urdf" /
                          "GEN3-7DOF-NOVISION_FOR_URDF_ARM_V12.urdf";
  if (!fs::exists(kinova)) GTEST_SKIP() << kinova << " is absent";
  SceneOptions options;
  options.package_paths = {(robots / "kinova_gen3").string()};
  expect_every_corner_covered(load_scene(kinova.string(), {}, options), "Kinova Gen3");
}

}  // namespace
}  // namespace tofguard::robot_model
