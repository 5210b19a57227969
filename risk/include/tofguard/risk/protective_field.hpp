#pragma once
// The protective and warning fields (docs/safety-chain.md, "Protective
// fields"): speed and separation monitoring as ISO 13855 and ISO/TS 15066
// size it. The protective separation
//   S = K * (T_r + T_s) + v_arm * T_r + S_s + C
// K: the speed at which a person approaches (risk.field.approach_speed),
// T_r: the chain's response time (chain_response_time_s), T_s and S_s: the
// robot's stopping time and distance, C: the intrusion distance (reach
// through the detection capability), v_arm: a bound on the arm's fastest
// surface point at the frame (arm_speed_bound_m_s). An unexplained surface
// nearer than S stops the arm (UNKNOWN_OBJECT); within S + warning_margin
// it warns; beyond, it is nobody's concern, whatever its size.
//
// Units: metres, seconds, m/s. Pure logic: no LCM, no clocks.
#include <limits>
#include <optional>
#include <string>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

// T_r: from a person entering the field to the stop leaving tofguard, s:
// one frame period (the person may step in just after a capture), then
// debounce_frames frames to confirm, then the chain's latency from a
// frame's capture to the stop output (risk.field.chain_latency_ms).
double chain_response_time_s(const RiskSettings& risk, double camera_rate_hz);

// v_arm, m/s: sum_j |speed_j| * frame.joint_reach_m[j] over the frame's
// joints (discrepancy_t.joint_name), with each joint's speed from `state`
// (the joint state at the frame's capture; rad/s, m/s for prismatic
// joints). +infinity when it cannot be bounded: no state, a joint the state
// does not report with a speed, or no reach (no cover or no kinematics in
// the labels: field_available false or num_joints 0).
double arm_speed_bound_m_s(const discrepancy_t& frame, const joint_state_t* state,
                           std::string* why = nullptr);

struct FieldSize {
  // Unknown until sized: a field never sized protects everything in range.
  double arm_speed_m_s = std::numeric_limits<double>::infinity();
  double response_time_s = 0;
  // S, and S + warning_margin, m (+infinity for an unbounded arm speed).
  double protective_m = std::numeric_limits<double>::infinity();
  double warning_m = std::numeric_limits<double>::infinity();
};
FieldSize field_size(const RiskSettings& risk, double response_time_s, double arm_speed_m_s);

// Speed and separation monitoring with speed scaling (ISO/TS 15066 5.5.4):
// the highest arm speed v_arm (m/s) whose S still fits `separation_m`, S
// solved for v_arm: (separation - K (T_r + T_s) - S_s - C) / T_r; 0 when
// even the arm at rest needs more than `separation_m`.
double highest_arm_speed_for_separation_m_s(const RiskSettings& risk, double response_time_s,
                                            double separation_m);

// The distance (m) of the nearest unexplained surface that counts as an
// object: the first field bin's outer edge at which the cumulative area
// (discrepancy_t.unexplained_area_within_m2) reaches `min_area_m2`;
// nullopt when none does within the frame's range.
std::optional<double> object_distance_m(const discrepancy_t& frame, double min_area_m2);

// The frame's field range, m: num_field_bins * field_bin_m.
double field_range_m(const discrepancy_t& frame);

// (iso13855_intrusion_distance_m, the C the config must at least give, is
// in risk_settings.hpp: the reader checks risk.field.intrusion_distance_m
// against it.)

}  // namespace tofguard::risk
