// The seated user beside the default arm's nominal motion (config/sim.yaml's
// joints_sim, the occupant of tests/support/occupant_test_config.hpp): the
// separation from the arm's cover to each body region along a minute of
// the motion, and what the body-region rules permit there
// (docs/safety-chain.md, "The user").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "joint_motion.hpp"
#include "judge_campaign.hpp"
#include "occupant_test_config.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/risk/body_region_rules.hpp"
#include "tofguard/risk/protective_field.hpp"
#include "tofguard/robot_model/arm_spheres.hpp"
#include "tofguard/robot_model/kinematics.hpp"
#include "tofguard/robot_model/occupant_model.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

using namespace robot_model;

JointPositions joints_at(const sim::JointsSimSettings& sim, double t_s) {
  JointPositions q;
  for (const sim::JointMotion& m : sim.motion) q[m.joint] = joint_position(m, t_s);
  return q;
}

struct RegionFigures {
  double min_separation_m = 1e9;   // to the model, cover to shapes
  double min_permitted_m_s = 1e9;  // at the separation to the envelope
  int samples_over_limit = 0;      // the arm's fastest sphere faster than permitted
};

// A minute of `arm`'s nominal motion (joints_sim.motion) at 20 Hz beside
// the occupant of `occupant_settings` seated at `world_from_seat`: per body
// region the smallest separation, the smallest permitted speed (the rules
// sized with the arm's own moving mass) and the samples whose fastest
// sphere is faster than permitted. Printed, one line per region.
std::map<BodyRegion, RegionFigures> region_figures(const deployment::Config& arm,
                                                   const OccupantSettings& occupant_settings,
                                                   const Eigen::Isometry3d& world_from_seat, int* samples) {
  SceneOptions options;  // the defaults, with the robot's packages
  options.package_paths = arm.robot.package_paths;
  const SceneModel scene = load_scene(arm.robot.urdf_path, arm.environment.urdf_paths, options);
  const ArmSpheres cover = cover_arm_with_spheres(scene, arm.renderer.arm_cover_cell_m);
  const OccupantModel occupant = load_occupant(occupant_settings.urdf_path, world_from_seat);
  std::map<BodyRegion, risk::BodyRegionRule> rules;
  for (const auto& rule : risk::body_region_rules(occupant_settings, moving_mass_kg(scene)))
    rules[rule.region] = rule;
  const double t_r = risk::chain_response_time_s(arm.risk, arm.camera.rate_hz);
  const double t_s = arm.risk.field_stopping_time_us * 1e-6;
  const double z_m = 0.05;  // sin 3 deg x a 1 m reach (docs/safety-chain.md, "The user")

  std::map<BodyRegion, RegionFigures> figures;
  constexpr double kDtS = 0.05;
  *samples = 1200;  // a minute
  PlacedArmSpheres before = place_arm_spheres(cover, forward_kinematics(scene, joints_at(arm.joints_sim, 0)));
  for (int i = 1; i <= *samples; ++i) {
    const PlacedArmSpheres placed =
        place_arm_spheres(cover, forward_kinematics(scene, joints_at(arm.joints_sim, i * kDtS)));
    double arm_speed_m_s = 0;  // the fastest sphere's, over the step
    for (size_t k = 0; k < placed.size(); ++k) {
      arm_speed_m_s =
          std::max(arm_speed_m_s, (placed[k].center_world_m - before[k].center_world_m).norm() / kDtS);
    }
    for (const auto& [region, d] : body_region_separations_m(placed, occupant)) {
      const risk::BodyRegionRule& rule = rules.at(region);
      const double permitted =
          risk::permitted_arm_speed_m_s(rule, std::max(0.0, d - rule.envelope_m), z_m, t_r, t_s);
      RegionFigures& f = figures[region];
      f.min_separation_m = std::min(f.min_separation_m, d);
      f.min_permitted_m_s = std::min(f.min_permitted_m_s, permitted);
      if (arm_speed_m_s > permitted) ++f.samples_over_limit;
    }
    before = placed;
  }
  std::printf("%s (moving mass %.2f kg):\n", arm.robot.urdf_path.c_str(), moving_mass_kg(scene));
  for (const auto& [region, f] : figures) {
    std::printf(
        "  %-18s separation >= %.3f m, permitted >= %.2f m/s, faster than permitted on %d of %d samples\n",
        body_region_name(region), f.min_separation_m, f.min_permitted_m_s, f.samples_over_limit, *samples);
  }
  return figures;
}

// The arm never passes through the user's model, and the head and the neck
// stay far enough that the nominal motion never has to stand for them.
void expect_the_user_kept(const std::map<BodyRegion, RegionFigures>& figures) {
  ASSERT_EQ(figures.size(), static_cast<size_t>(kNumBodyRegions));
  for (const BodyRegion region : all_body_regions()) {
    EXPECT_GT(figures.at(region).min_separation_m, 0) << body_region_name(region);
    if (body_region_is_no_contact(region)) {
      EXPECT_GT(figures.at(region).min_permitted_m_s, 0) << body_region_name(region);
    }
  }
}

TEST(OccupantSeparation, TheDefaultArmsNominalMotionNeverNeedsToStandForTheHeadOrNeck) {
  const deployment::Config config =
      deployment::load_config(sim_config_variant("occupant-separation", {}, occupant_section()), nullptr);
  ASSERT_TRUE(config.occupant.has_value());
  const SceneModel scene = load_scene(config.robot.urdf_path, config.environment.urdf_paths, {});
  int samples = 0;
  const auto figures =
      region_figures(config, *config.occupant, fixed_link_pose(scene, config.occupant->seated_on), &samples);
  expect_the_user_kept(figures);
}

// The iiwa14 and the Kinova Gen3 (the campaign's scenes and motions, the
// robot's root at the world origin) with the same user seated beside each:
// facing along x, the seat's origin 0.55 m to the arm's left (+y) and
// 0.25 m behind its base, as the default arm stands beside the armrest.
// The rules are sized with each arm's own mass (docs/safety-chain.md's
// table); the figures are printed and the user kept as for the default.
TEST(OccupantSeparation, TheIiwa14AndTheKinovaGen3BesideASeatedUser) {
  const std::string scenes = output_dir() + "/occupant-separation-scenes";
  const std::vector<std::optional<CampaignArm>> arms = {iiwa14_campaign_arm(shared_dir(), scenes),
                                                        kinova_gen3_campaign_arm(shared_dir(), scenes)};
  if (!arms[0] || !arms[1]) {
    GTEST_SKIP() << "the iiwa14 or the Kinova Gen3 is not under ../shared/robots (shared_dir() '"
                 << shared_dir() << "')";
  }
  const deployment::Config with_user = deployment::load_config(
      sim_config_variant("occupant-separation-user", {}, occupant_section()), nullptr);
  const Eigen::Isometry3d world_from_seat(Eigen::Translation3d(-0.25, 0.55, 0.0));
  for (const auto& arm : arms) {
    SCOPED_TRACE(arm->name);
    int samples = 0;
    const auto figures = region_figures(arm->config, *with_user.occupant, world_from_seat, &samples);
    expect_the_user_kept(figures);
  }
}

}  // namespace
}  // namespace tofguard::test
