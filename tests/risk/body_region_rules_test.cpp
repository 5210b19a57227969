// The user's body-region rules: ISO/TS 15066 Annex A's permissible contact
// speeds for the arms' effective masses (figures worked by hand below), the
// permitted speed as the separation closes, and speed scaling for the
// protective field.
#include <gtest/gtest.h>

#include "tofguard/risk/body_region_rules.hpp"
#include "tofguard/risk/protective_field.hpp"

namespace tofguard::risk::test {
namespace {

// The moving masses robot_model's occupant_model_test reads from the URDFs.
constexpr double kDefaultArmKg = 10.0;
constexpr double kIiwa14Kg = 25.61;
constexpr double kKinovaGen3Kg = 6.353;
constexpr double kPayloadKg = 0.5;

double contact_speed(BodyRegion region, double moving_mass_kg) {
  return permissible_contact_speed_m_s(iso_ts_15066_limits(region),
                                       robot_effective_mass_kg(moving_mass_kg, kPayloadKg), 1.0);
}

TEST(BodyRegionRules, ContactSpeedsOfTheThreeArms) {
  // Default arm: m_R = 10/2 + 0.5 = 5.5 kg.
  //  hand: mu = 1/(1/0.6 + 1/5.5) = 0.5410 kg, sqrt(mu * 75000) = 201.4,
  //        v = 140 / 201.4 = 0.695 m/s;
  //  chest: mu = 1/(1/40 + 1/5.5) = 4.835 kg, sqrt(mu * 25000) = 347.7,
  //        v = 140 / 347.7 = 0.403 m/s;
  //  abdomen: the same mu, sqrt(mu * 10000) = 219.9, v = 110 / 219.9 = 0.500;
  //  forearm: mu = 1/(1/2 + 1/5.5) = 1.467 kg, sqrt(mu * 40000) = 242.2,
  //        v = 160 / 242.2 = 0.661 m/s.
  EXPECT_NEAR(robot_effective_mass_kg(kDefaultArmKg, kPayloadKg), 5.5, 1e-12);
  EXPECT_NEAR(contact_speed(BodyRegion::kHand, kDefaultArmKg), 0.695, 0.001);
  EXPECT_NEAR(contact_speed(BodyRegion::kChest, kDefaultArmKg), 0.403, 0.001);
  EXPECT_NEAR(contact_speed(BodyRegion::kAbdomen, kDefaultArmKg), 0.500, 0.001);
  EXPECT_NEAR(contact_speed(BodyRegion::kForearm, kDefaultArmKg), 0.661, 0.001);
  // iiwa14: m_R = 12.805 + 0.5 = 13.305 kg; chest: mu = 9.984 kg,
  // sqrt(mu * 25000) = 499.6, v = 140 / 499.6 = 0.280 m/s.
  EXPECT_NEAR(contact_speed(BodyRegion::kChest, kIiwa14Kg), 0.280, 0.001);
  // Kinova Gen3: m_R = 3.1765 + 0.5 = 3.6765 kg; hand: mu = 0.5158 kg,
  // sqrt(mu * 75000) = 196.7, v = 140 / 196.7 = 0.712 m/s.
  EXPECT_NEAR(contact_speed(BodyRegion::kHand, kKinovaGen3Kg), 0.712, 0.001);
  // A transient contact (factor 2) doubles it.
  EXPECT_NEAR(permissible_contact_speed_m_s(iso_ts_15066_limits(BodyRegion::kHand),
                                            robot_effective_mass_kg(kDefaultArmKg, kPayloadKg), 2.0),
              2 * 0.695, 0.002);
  // A heavier arm is allowed less, for every region.
  for (const BodyRegion region : all_body_regions()) {
    EXPECT_LT(contact_speed(region, kIiwa14Kg), contact_speed(region, kDefaultArmKg))
        << body_region_name(region);
    EXPECT_LT(contact_speed(region, kDefaultArmKg), contact_speed(region, kKinovaGen3Kg))
        << body_region_name(region);
  }
}

OccupantSettings occupant() {
  OccupantSettings o;
  o.payload_kg = kPayloadKg;
  o.contact_force_factor = 1.0;
  for (const BodyRegion region : all_body_regions()) o.regions[region].envelope_m = 0.05;
  o.regions[BodyRegion::kSkullAndForehead].clearance_m = 0.05;
  o.regions[BodyRegion::kFace].clearance_m = 0.03;
  o.regions[BodyRegion::kNeck].clearance_m = 0.05;
  return o;
}

const BodyRegionRule& rule_of(const std::vector<BodyRegionRule>& rules, BodyRegion region) {
  for (const BodyRegionRule& r : rules) {
    if (r.region == region) return r;
  }
  throw std::runtime_error("no rule");
}

TEST(BodyRegionRules, TheHeadAndNeckGetAClearanceTheRestAContactSpeed) {
  const std::vector<BodyRegionRule> rules = body_region_rules(occupant(), kDefaultArmKg);
  ASSERT_EQ(rules.size(), static_cast<size_t>(kNumBodyRegions));
  const BodyRegionRule& face = rule_of(rules, BodyRegion::kFace);
  EXPECT_FALSE(face.contact_allowed);
  EXPECT_DOUBLE_EQ(face.contact_speed_m_s, 0);
  EXPECT_DOUBLE_EQ(face.clearance_m, 0.03);
  const BodyRegionRule& hand = rule_of(rules, BodyRegion::kHand);
  EXPECT_TRUE(hand.contact_allowed);
  EXPECT_NEAR(hand.contact_speed_m_s, 0.695, 0.001);
  EXPECT_DOUBLE_EQ(hand.clearance_m, 0);
}

TEST(BodyRegionRules, ThePermittedSpeedFallsWithTheSeparation) {
  const std::vector<BodyRegionRule> rules = body_region_rules(occupant(), kDefaultArmKg);
  const BodyRegionRule& face = rule_of(rules, BodyRegion::kFace);
  // T_r 0.193 s and T_s 0.15 s (config/sim.yaml at 30 Hz), the arm's
  // position uncertain by 5 cm: (d - 0.03 - 0.05) / 0.343.
  const double t_r = 0.193, t_s = 0.15, z = 0.05;
  EXPECT_NEAR(permitted_arm_speed_m_s(face, 0.18, z, t_r, t_s), 0.10 / 0.343, 1e-9);  // 0.29 m/s
  EXPECT_NEAR(permitted_arm_speed_m_s(face, 0.50, z, t_r, t_s), 0.42 / 0.343, 1e-9);
  EXPECT_DOUBLE_EQ(permitted_arm_speed_m_s(face, 0.08, z, t_r, t_s), 0);  // clearance and uncertainty: stand
  EXPECT_DOUBLE_EQ(permitted_arm_speed_m_s(face, 0.0, z, t_r, t_s), 0);
  // Where contact is allowed the arm keeps its contact speed down to 0.
  const BodyRegionRule& chest = rule_of(rules, BodyRegion::kChest);
  EXPECT_NEAR(permitted_arm_speed_m_s(chest, 0.0, z, t_r, t_s), 0.403, 0.001);
  EXPECT_NEAR(permitted_arm_speed_m_s(chest, 0.50, z, t_r, t_s), 0.45 / 0.343, 1e-9);
}

TEST(ProtectiveField, SpeedScalingIsTheFieldSolvedForTheArmSpeed) {
  RiskSettings risk;
  risk.field_approach_speed_m_s = 1.6;
  risk.field_stopping_time_us = 150'000;
  risk.field_stopping_distance_m = 0.03;
  risk.field_intrusion_distance_m = 0.2;
  const double t_r = 0.193;
  // S at rest = 1.6 * 0.343 + 0.03 + 0.2 = 0.7788 m.
  EXPECT_NEAR(highest_arm_speed_for_separation_m_s(risk, t_r, 0.9), (0.9 - 0.7788) / t_r, 1e-9);  // 0.63 m/s
  EXPECT_DOUBLE_EQ(highest_arm_speed_for_separation_m_s(risk, t_r, 0.7), 0);
  for (const double v : {0.0, 0.1, 0.5, 2.0}) {
    const double s = field_size(risk, t_r, v).protective_m;
    EXPECT_NEAR(highest_arm_speed_for_separation_m_s(risk, t_r, s), v, 1e-9);
  }
}

}  // namespace
}  // namespace tofguard::risk::test
