#pragma once
// The rules that protect the wheelchair's occupant, per body region
// (docs/safety-chain.md, "The user"): how fast the arm may move at a given
// separation from a region of the user, so that it either stops before the
// region's clearance is gone or, where contact is allowed, touches the
// region no harder than ISO/TS 15066 Annex A permits.
//
// Contact (ISO/TS 15066:2016 Annex A, A.3 and A.4): a transient contact
// turns the relative kinetic energy into the body's deformation,
//   1/2 mu v^2 = F^2 / (2 k),   so   v_contact = F / sqrt(mu k),
// with k the region's effective spring constant, F the permitted force
// (contact_force_factor times the region's quasi-static limit),
// mu = (1/m_H + 1/m_R)^-1 the reduced mass of the region's effective mass
// m_H and the robot's, m_R = M/2 + m_L (M the moving mass of the arm, m_L
// its payload).
//
// Separation: at a separation d (from the arm's cover to the region's
// envelope, metres) the arm at speed v travels at most v (T_r + T_s)
// before it stands: T_r the chain's response time (risk/
// protective_field.hpp), T_s the robot's stopping time, during which its
// stopping distance is at most v T_s. It keeps the clearance c and the
// uncertainty of where the arm is, z, when
//   v <= (d - c - z) / (T_r + T_s).
// The permitted speed is the larger of that and, for a region that may be
// touched, v_contact: either the arm stops (or slows to v_contact) in time,
// or its contact is within the region's limits.
//
// Units: metres, seconds, kg, N, m/s. Pure logic: no LCM, no clocks.
#include <string>
#include <vector>

#include "tofguard/common/body_region.hpp"
#include "tofguard/settings/occupant_settings.hpp"

namespace tofguard::risk {

// ISO/TS 15066:2016 Annex A for one body region: Table A.2's maximum
// permissible quasi-static contact force (N) and Table A.3's effective
// spring constant (N/mm) and effective mass (kg).
struct BodyRegionLimits {
  double quasi_static_force_n = 0;
  double spring_constant_n_per_mm = 0;
  double effective_mass_kg = 0;
};
BodyRegionLimits iso_ts_15066_limits(BodyRegion region);

// m_R = M/2 + m_L, kg (ISO/TS 15066 A.3.4).
double robot_effective_mass_kg(double moving_mass_kg, double payload_kg);
// mu = (1/a + 1/b)^-1, kg.
double reduced_mass_kg(double a_kg, double b_kg);
// v_contact = F / sqrt(mu k), m/s, with F = force_factor * the quasi-static
// force and k in N/m.
double permissible_contact_speed_m_s(const BodyRegionLimits& limits, double robot_effective_mass_kg,
                                     double force_factor);

// One region's rule, from the config and the arm's moving mass.
struct BodyRegionRule {
  BodyRegion region = BodyRegion::kChest;
  double envelope_m = 0;
  // True for a region the arm may touch (then clearance_m is 0 unless the
  // config gives one, and contact_speed_m_s > 0); false for the head and
  // the neck (contact_speed_m_s 0).
  bool contact_allowed = false;
  double clearance_m = 0;
  double contact_speed_m_s = 0;
};
std::vector<BodyRegionRule> body_region_rules(const OccupantSettings& occupant, double moving_mass_kg);

// The highest arm speed (m/s) permitted at `separation_m` from the rule's
// region (from the arm's cover to the region's envelope), with the arm's
// position uncertain by `uncertainty_m`, the chain's response time and the
// robot's stopping time (s). Never negative: 0 where the arm must stand.
double permitted_arm_speed_m_s(const BodyRegionRule& rule, double separation_m, double uncertainty_m,
                               double response_time_s, double stopping_time_s);

}  // namespace tofguard::risk
