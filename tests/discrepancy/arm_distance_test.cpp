// discrepancy/arm_distance.hpp: distances from seen points to the arm's
// cover as the labels carry it, and the joints' reach that bounds the arm's
// speed. On a hand-made cover against brute force, and on the default arm,
// the iiwa14 and the Kinova Gen3 rendered as tofguard-renderer renders them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "judge_campaign.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/discrepancy/arm_distance.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tool_support.hpp"

namespace tofguard::discrepancy {
namespace {

link_labels_t labels_with_spheres(const std::vector<std::pair<int, Eigen::Vector4d>>& spheres,
                                  int num_robot_links) {
  link_labels_t l{};
  l.num_robot_links = num_robot_links;
  l.num_links = num_robot_links;
  for (const auto& [link, s] : spheres) {
    l.arm_sphere_link.push_back(static_cast<int16_t>(link));
    l.arm_sphere_center_m.push_back(
        {static_cast<float>(s[0]), static_cast<float>(s[1]), static_cast<float>(s[2])});
    l.arm_sphere_radius_m.push_back(static_cast<float>(s[3]));
    l.arm_cover_max_radius_m = std::max(l.arm_cover_max_radius_m, s[3]);
  }
  l.num_arm_spheres = static_cast<int32_t>(spheres.size());
  return l;
}

TEST(ArmDistance, EqualsTheNearestSphereByBruteForceUpToTheSearchLimit) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-0.5, 0.5);
  std::uniform_real_distribution<double> radius(0.005, 0.03);
  std::uniform_int_distribution<int> link(0, 4);
  std::vector<std::pair<int, Eigen::Vector4d>> spheres;
  for (int k = 0; k < 300; ++k) {
    const int l = link(rng);
    // Each link's spheres about its own centre, as a link's are.
    spheres.push_back({l, Eigen::Vector4d(0.3 * l + 0.2 * coordinate(rng), 0.2 * coordinate(rng),
                                          1.5 + 0.2 * coordinate(rng), radius(rng))});
  }
  const link_labels_t labels = labels_with_spheres(spheres, 5);
  const ArmDistance arm(labels);
  ASSERT_FALSE(arm.empty());
  for (int n = 0; n < 2000; ++n) {
    const Eigen::Vector3d p(3 * coordinate(rng), 3 * coordinate(rng), 1.5 + 3 * coordinate(rng));
    double truth = std::numeric_limits<double>::infinity();
    for (int k = 0; k < labels.num_arm_spheres; ++k) {
      const Eigen::Vector3d c(labels.arm_sphere_center_m[k][0], labels.arm_sphere_center_m[k][1],
                              labels.arm_sphere_center_m[k][2]);
      truth = std::min(truth, (p - c).norm() - labels.arm_sphere_radius_m[k]);
    }
    truth = std::max(0.0, truth);
    EXPECT_NEAR(arm.distance_m(p, 10.0), truth, 1e-9);
    // Searched only up to 0.5 m: exact within it, at least 0.5 m beyond.
    const double limited = arm.distance_m(p, 0.5);
    if (truth < 0.5) {
      EXPECT_NEAR(limited, truth, 1e-9);
    } else {
      EXPECT_GE(limited, 0.5 - 1e-12);
    }
  }
  EXPECT_TRUE(std::isinf(ArmDistance(link_labels_t{}).distance_m(Eigen::Vector3d::Zero(), 1.0)));
}

TEST(ArmDistance, JointReachOfATwoAxisArm) {
  // Link 0 fixed, link 1 turned by axis 0 (joint j0, about optical x
  // through the origin), link 2 by axis 1 (j1, about optical y through
  // (0, 0, 1)) below axis 0, and a prismatic axis 2 (j2, mimicking 2x)
  // moving link 3 below axis 1.
  std::vector<std::pair<int, Eigen::Vector4d>> spheres = {
      {0, {5, 5, 5, 0.1}}, {1, {0, 0.3, 0, 0.02}}, {2, {0.4, 0, 1, 0.05}}, {3, {0.4, 0.2, 1, 0.01}}};
  link_labels_t l = labels_with_spheres(spheres, 4);
  l.num_joints = 3;
  l.joint_name = {"j0", "j1", "j2"};
  l.num_axes = 3;
  l.axis_joint = {0, 1, 2};
  l.axis_multiplier = {1, 1, 2};
  l.axis_prismatic = {false, false, true};
  l.axis_origin_m = {{0, 0, 0}, {0, 0, 1}, {0.4, 0, 1}};
  l.axis_direction = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  l.axis_parent = {-1, 0, 1};
  l.num_link_axes = 4;
  l.link_axis = {-1, 0, 1, 2};
  ASSERT_EQ(check_link_labels([&] {
              link_labels_t checked = l;
              checked.utime = 1;
              checked.usable = true;
              checked.width = 1;
              checked.height = 1;
              checked.num_pixels = 1;
              checked.label = {0};
              checked.link_name = {"l0", "l1", "l2", "l3"};
              return checked;
            }()),
            "");
  const std::vector<double> reach = joint_reach_m(l);
  ASSERT_EQ(reach.size(), 3u);
  // j0 moves links 1..3: farthest from the x axis: link 2's sphere, 1 +
  // 0.05 (link 3's: sqrt(0.2^2 + 1^2) + 0.01 = 1.03).
  EXPECT_NEAR(reach[0], 1.05, 1e-6);
  // j1 moves links 2, 3: off the y axis through (0,0,1): 0.4 + 0.05.
  EXPECT_NEAR(reach[1], 0.45, 1e-6);
  // j2 prismatic, multiplier 2: 2 m/s per m/s.
  EXPECT_DOUBLE_EQ(reach[2], 2.0);
  l.num_axes = 0;
  EXPECT_TRUE(joint_reach_m(l).empty());
}

// On each arm of the campaign: the cover the renderer sends holds every
// rendered robot pixel's surface point (distance ~0), and the joints' reach
// bounds how fast any sphere moves for a random joint velocity.
void expect_cover_holds_the_rendered_arm(const test::CampaignArm& arm) {
  SCOPED_TRACE(arm.name);
  const deployment::Config& config = arm.config;
  const robot_model::SceneModel scene =
      robot_model::load_scene(config.robot.urdf_path, config.environment.urdf_paths, [&] {
        robot_model::SceneOptions o;
        o.package_paths = config.robot.package_paths;
        return o;
      }());
  const robot_model::ArmSpheres cover =
      robot_model::cover_arm_with_spheres(scene, config.renderer.arm_cover_cell_m);
  renderer::DepthRenderer renderer(scene, config.renderer.near_m, config.renderer.far_m);
  robot_model::JointPositions q;
  for (const sim::JointMotion& m : config.joints_sim.motion) q[m.joint] = m.center + 0.5 * m.amplitude;
  const Intrinsics intrinsics = config.camera.intrinsics;
  // The campaign's camera pose is given in the world (the robot's root).
  const renderer::RenderResult result = renderer.render_at(
      robot_model::forward_kinematics(scene, q), config.camera.pose.frame_from_optical(), intrinsics);
  ASSERT_TRUE(result.usable) << result.unusable_reason;
  const depth_image_t frame = make_depth_image(config.camera.id, intrinsics, 1, 1, true, result.depth_m);
  const link_labels_t labels = renderer::make_rendered_link_labels(frame, result, scene, cover);
  ASSERT_EQ(check_link_labels(labels), "");
  ASSERT_GT(labels.num_arm_spheres, 0);
  ASSERT_GT(labels.num_axes, 0);
  const ArmDistance distance(labels);
  int robot_pixels = 0;
  double worst_m = 0;
  for (int i = 0; i < intrinsics.width * intrinsics.height; ++i) {
    const int l = labels.label[i];
    if (l < link_labels_t::ROBOT_FIRST || l >= link_labels_t::ROBOT_FIRST + labels.num_robot_links) continue;
    const double z = result.depth_m[i];
    const Eigen::Vector3d p((i % intrinsics.width - intrinsics.cx) * z / intrinsics.fx,
                            (i / intrinsics.width - intrinsics.cy) * z / intrinsics.fy, z);
    worst_m = std::max(worst_m, distance.distance_m(p, 1.0));
    ++robot_pixels;
  }
  EXPECT_GT(robot_pixels, 100);
  // The rendered surface lies on the arm's triangles; float depth: < 0.1 mm.
  EXPECT_LT(worst_m, 1e-4) << robot_pixels << " robot pixels";

  // Speed: the spheres placed at q and at q + dt * qdot move at most
  // sum_j |qdot_j| * reach_j (the bound is loose; it must hold).
  const std::vector<double> reach = joint_reach_m(labels);
  ASSERT_EQ(reach.size(), static_cast<size_t>(labels.num_joints));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> speed(-1.0, 1.0);
  const Eigen::Isometry3d world_from_optical = result.world_from_optical;
  for (int trial = 0; trial < 20; ++trial) {
    robot_model::JointPositions moved = q;
    double bound_m_s = 0;
    constexpr double kDt = 1e-5;
    for (int j = 0; j < labels.num_joints; ++j) {
      const double qdot = speed(rng);
      moved[labels.joint_name[j]] += qdot * kDt;
      bound_m_s += std::abs(qdot) * reach[j];
    }
    const renderer::RenderedArmCover before =
        renderer::rendered_arm_cover(cover, robot_model::forward_kinematics(scene, q), world_from_optical);
    const renderer::RenderedArmCover after = renderer::rendered_arm_cover(
        cover, robot_model::forward_kinematics(scene, moved), world_from_optical);
    double fastest_m_s = 0;
    for (size_t k = 0; k < before.spheres.size(); ++k) {
      fastest_m_s =
          std::max(fastest_m_s, (after.spheres[k].center_m - before.spheres[k].center_m).norm() / kDt);
    }
    EXPECT_LE(fastest_m_s, bound_m_s * (1 + 1e-4)) << "trial " << trial;
    EXPECT_GT(fastest_m_s, 0.1 * bound_m_s)
        << "trial " << trial << ": the bound should not be absurdly loose";
  }
}

TEST(ArmDistance, TheRenderersCoverHoldsTheRenderedArmOnEachArm) {
  expect_cover_holds_the_rendered_arm(test::default_campaign_arm());
  if (test::shared_dir().empty()) {
    GTEST_SKIP() << "../shared is absent: the iiwa14 and Kinova Gen3 models are not available";
  }
  const std::string scene_dir = testing::TempDir();
  const auto iiwa = test::iiwa14_campaign_arm(test::shared_dir(), scene_dir);
  const auto kinova = test::kinova_gen3_campaign_arm(test::shared_dir(), scene_dir);
  if (!iiwa || !kinova) GTEST_SKIP() << "the iiwa14 or the Kinova Gen3 files are absent in ../shared/robots";
  expect_cover_holds_the_rendered_arm(*iiwa);
  expect_cover_holds_the_rendered_arm(*kinova);
}

}  // namespace
}  // namespace tofguard::discrepancy
