// The seated user beside the default arm's nominal motion (config/sim.yaml's
// joints_sim, the occupant of tests/support/occupant_test_config.hpp): the
// separation from the arm's cover to each body region along a minute of
// the motion, and what the body-region rules permit there
// (docs/safety-chain.md, "The user").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

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
  for (const sim::JointMotion& m : sim.motion) {
    q[m.joint] = m.center + m.amplitude * std::sin(2 * M_PI * t_s / m.period_s + m.phase_rad);
  }
  return q;
}

struct RegionFigures {
  double min_separation_m = 1e9;   // to the model, cover to shapes
  double min_permitted_m_s = 1e9;  // at the separation to the envelope
  int samples_over_limit = 0;      // the arm's fastest sphere faster than permitted
};

TEST(OccupantSeparation, TheDefaultArmsNominalMotionNeverNeedsToStandForTheHeadOrNeck) {
  const deployment::Config config =
      deployment::load_config(sim_config_variant("occupant-separation", {}, occupant_section()), nullptr);
  ASSERT_TRUE(config.occupant.has_value());
  const SceneModel scene = load_scene(config.robot.urdf_path, config.environment.urdf_paths, {});
  const ArmSpheres cover = cover_arm_with_spheres(scene, config.renderer.arm_cover_cell_m);
  const OccupantModel occupant =
      load_occupant(config.occupant->urdf_path, fixed_link_pose(scene, config.occupant->seated_on));
  std::map<BodyRegion, risk::BodyRegionRule> rules;
  for (const auto& rule : risk::body_region_rules(*config.occupant, moving_mass_kg(scene)))
    rules[rule.region] = rule;
  const double t_r = risk::chain_response_time_s(config.risk, config.camera.rate_hz);
  const double t_s = config.risk.field_stopping_time_us * 1e-6;
  const double z_m = 0.05;  // sin 3 deg x a 1 m reach (docs/safety-chain.md, "The user")

  std::map<BodyRegion, RegionFigures> figures;
  constexpr double kDtS = 0.05;
  constexpr int kSamples = 1200;  // a minute
  PlacedArmSpheres before =
      place_arm_spheres(cover, forward_kinematics(scene, joints_at(config.joints_sim, 0)));
  for (int i = 1; i <= kSamples; ++i) {
    const PlacedArmSpheres placed =
        place_arm_spheres(cover, forward_kinematics(scene, joints_at(config.joints_sim, i * kDtS)));
    double arm_speed_m_s = 0;  // the fastest sphere's, over the step
    for (size_t s = 0; s < placed.size(); ++s) {
      arm_speed_m_s =
          std::max(arm_speed_m_s, (placed[s].center_world_m - before[s].center_world_m).norm() / kDtS);
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
  for (const auto& [region, f] : figures) {
    std::printf(
        "%-18s separation >= %.3f m, permitted >= %.2f m/s, faster than permitted on %d of %d samples\n",
        body_region_name(region), f.min_separation_m, f.min_permitted_m_s, f.samples_over_limit, kSamples);
  }
  ASSERT_EQ(figures.size(), static_cast<size_t>(kNumBodyRegions));
  for (const BodyRegion region : all_body_regions()) {
    // The arm never passes through the user's model.
    EXPECT_GT(figures[region].min_separation_m, 0) << body_region_name(region);
    // The head and the neck stay far enough that the nominal motion
    // never has to stand for them.
    if (body_region_is_no_contact(region)) {
      EXPECT_GT(figures[region].min_permitted_m_s, 0) << body_region_name(region);
    }
  }
}

}  // namespace
}  // namespace tofguard::test
