#include "tofguard/risk/protective_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tofguard::risk {

double chain_response_time_s(const RiskSettings& risk, double camera_rate_hz) {
  return (1.0 + risk.debounce_frames) / camera_rate_hz + risk.field_chain_latency_us * 1e-6;
}

double arm_speed_bound_m_s(const discrepancy_t& frame, const joint_state_t* state, std::string* why) {
  constexpr double kUnbounded = std::numeric_limits<double>::infinity();
  const auto refuse = [&](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return kUnbounded;
  };
  if (!frame.field_available) return refuse("the labels carried no arm cover or kinematics");
  if (state == nullptr) return refuse("no joint state at the frame's capture time");
  if (frame.num_joints <= 0 || frame.joint_reach_m.size() != static_cast<size_t>(frame.num_joints)) {
    return refuse("the labels carried no kinematics, so no joint reach");
  }
  double speed = 0;
  for (int j = 0; j < frame.num_joints; ++j) {
    const auto at = std::find(state->name.begin(), state->name.end(), frame.joint_name[j]);
    const auto index = static_cast<size_t>(at - state->name.begin());
    if (at == state->name.end() || index >= state->velocity.size() ||
        !std::isfinite(state->velocity[index])) {
      return refuse("joint '" + frame.joint_name[j] + "' has no speed in the joint state");
    }
    speed += std::abs(state->velocity[index]) * frame.joint_reach_m[j];
  }
  return speed;
}

FieldSize field_size(const RiskSettings& risk, double response_time_s, double arm_speed_m_s) {
  FieldSize f;
  f.arm_speed_m_s = arm_speed_m_s;
  f.response_time_s = response_time_s;
  const double stopping_time_s = risk.field_stopping_time_us * 1e-6;
  f.protective_m = risk.field_approach_speed_m_s * (response_time_s + stopping_time_s) +
                   arm_speed_m_s * response_time_s + risk.field_stopping_distance_m +
                   risk.field_intrusion_distance_m;
  f.warning_m = f.protective_m + risk.field_warning_margin_m;
  return f;
}

double highest_arm_speed_for_separation_m_s(const RiskSettings& risk, double response_time_s,
                                            double separation_m) {
  const double at_rest_m = field_size(risk, response_time_s, 0).protective_m;
  return std::max(0.0, (separation_m - at_rest_m) / response_time_s);
}

std::optional<double> object_distance_m(const discrepancy_t& frame, double min_area_m2) {
  for (int k = 0; k < frame.num_field_bins; ++k) {
    if (frame.unexplained_area_within_m2[k] >= min_area_m2)
      return (k + 1) * static_cast<double>(frame.field_bin_m);
  }
  return std::nullopt;
}

double field_range_m(const discrepancy_t& frame) {
  return frame.num_field_bins * static_cast<double>(frame.field_bin_m);
}

}  // namespace tofguard::risk
