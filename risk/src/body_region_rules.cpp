#include "tofguard/risk/body_region_rules.hpp"

#include <algorithm>
#include <cmath>

#include "tofguard/common/demand.hpp"

namespace tofguard::risk {

BodyRegionLimits iso_ts_15066_limits(BodyRegion region) {
  // ISO/TS 15066:2016, Table A.2 (quasi-static force, N) and Table A.3
  // (effective spring constant, N/mm; effective mass, kg). The neck's
  // spring constant is its sides' (50 N/mm; the front, the larynx, 10):
  // the neck gets a clearance, so only its envelope and clearance are used.
  switch (region) {
    case BodyRegion::kSkullAndForehead:
      return {130, 150, 4.4};
    case BodyRegion::kFace:
      return {65, 75, 4.4};
    case BodyRegion::kNeck:
      return {150, 50, 1.2};
    case BodyRegion::kBackAndShoulders:
      return {210, 35, 40};
    case BodyRegion::kChest:
      return {140, 25, 40};
    case BodyRegion::kAbdomen:
      return {110, 10, 40};
    case BodyRegion::kPelvis:
      return {180, 25, 40};
    case BodyRegion::kUpperArm:
      return {150, 30, 3};
    case BodyRegion::kForearm:
      return {160, 40, 2};
    case BodyRegion::kHand:
      return {140, 75, 0.6};
    case BodyRegion::kThigh:
      return {220, 50, 75};
    case BodyRegion::kLowerLeg:
      return {130, 60, 75};
  }
  TOFGUARD_DEMAND(false, "a body region outside the enum");
  return {};
}

double robot_effective_mass_kg(double moving_mass_kg, double payload_kg) {
  return moving_mass_kg / 2 + payload_kg;
}

double reduced_mass_kg(double a_kg, double b_kg) { return 1.0 / (1.0 / a_kg + 1.0 / b_kg); }

double permissible_contact_speed_m_s(const BodyRegionLimits& limits, double robot_effective_mass_kg,
                                     double force_factor) {
  const double mu_kg = reduced_mass_kg(limits.effective_mass_kg, robot_effective_mass_kg);
  const double k_n_per_m = limits.spring_constant_n_per_mm * 1000;
  return force_factor * limits.quasi_static_force_n / std::sqrt(mu_kg * k_n_per_m);
}

std::vector<BodyRegionRule> body_region_rules(const OccupantSettings& occupant, double moving_mass_kg) {
  const double robot_kg = robot_effective_mass_kg(moving_mass_kg, occupant.payload_kg);
  std::vector<BodyRegionRule> rules;
  for (const auto& [region, settings] : occupant.regions) {
    BodyRegionRule rule;
    rule.region = region;
    rule.envelope_m = settings.envelope_m;
    rule.contact_allowed = !body_region_is_no_contact(region);
    rule.clearance_m = settings.clearance_m.value_or(0);
    if (rule.contact_allowed) {
      rule.contact_speed_m_s =
          permissible_contact_speed_m_s(iso_ts_15066_limits(region), robot_kg, occupant.contact_force_factor);
    }
    rules.push_back(rule);
  }
  return rules;
}

double permitted_arm_speed_m_s(const BodyRegionRule& rule, double separation_m, double uncertainty_m,
                               double response_time_s, double stopping_time_s) {
  const double stop_in_time_m_s =
      (separation_m - rule.clearance_m - uncertainty_m) / (response_time_s + stopping_time_s);
  return std::max({0.0, stop_in_time_m_s, rule.contact_speed_m_s});
}

}  // namespace tofguard::risk
