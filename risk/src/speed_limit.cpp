#include "tofguard/risk/speed_limit.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/risk/protective_field.hpp"

namespace tofguard::risk {
namespace {

speed_limit_t limit_base(const RiskSettings& risk, int64_t utime, int64_t seq, const std::string& camera_id) {
  speed_limit_t limit{};
  limit.utime = utime;
  limit.seq = seq;
  limit.camera_id = camera_id;
  limit.max_arm_speed_m_s = 0;
  limit.set_by = speed_limit_t::SET_BY_NO_JUDGEMENT;
  limit.separation_m = -1;
  limit.arm_speed_m_s = -1;
  limit.valid_for_ms = static_cast<int32_t>(risk.discrepancy_deadline_us / 1000);
  return limit;
}

// The rules' limit at the frame's regions, when lower than `limit`'s.
void limit_by_body_regions(const RiskSettings& risk, double response_time_s, const discrepancy_t& frame,
                           const std::vector<BodyRegionRule>& rules, speed_limit_t* limit) {
  double reach_m = 0;
  for (const double r : frame.joint_reach_m) reach_m = std::max(reach_m, r);
  const double uncertainty_m = std::sin(risk.evidence_joint_offset_rad) * reach_m;
  const double stopping_time_s = risk.field_stopping_time_us * 1e-6;
  for (const BodyRegionRule& rule : rules) {
    const std::string name = body_region_name(rule.region);
    const auto at = std::find(frame.body_region.begin(), frame.body_region.end(), name);
    if (at == frame.body_region.end()) {
      *limit = limit_base(risk, frame.utime, frame.seq, frame.camera_id);
      limit->reason = "stand: the frame has no separation from the user's " + name +
                      " (is the occupant configured where the arm is rendered?)";
      return;
    }
    const double separation_m =
        std::max(0.0, frame.body_region_separation_m[at - frame.body_region.begin()] - rule.envelope_m);
    const double permitted =
        permitted_arm_speed_m_s(rule, separation_m, uncertainty_m, response_time_s, stopping_time_s);
    if (permitted < limit->max_arm_speed_m_s) {
      limit->max_arm_speed_m_s = permitted;
      limit->set_by = speed_limit_t::SET_BY_BODY_REGION;
      limit->body_region = name;
      limit->separation_m = separation_m;
      limit->reason = "the user's " + name + " " + fixed(separation_m, 2) + " m from the arm: up to " +
                      fixed(permitted, 2) + " m/s";
    }
  }
}

}  // namespace

speed_limit_t frame_speed_limit(const RiskSettings& risk, double response_time_s, const discrepancy_t& frame,
                                double arm_speed_m_s, const std::vector<BodyRegionRule>& rules) {
  speed_limit_t limit = limit_base(risk, frame.utime, frame.seq, frame.camera_id);
  limit.arm_speed_m_s = std::isfinite(arm_speed_m_s) ? arm_speed_m_s : -1;
  if (!frame.usable) {
    limit.reason = "stand: the frame could not be compared (" + frame.unusable_reason + ")";
    return limit;
  }
  if (!frame.field_available) {
    limit.reason = "stand: the frame carries no distances to the arm (no cover in the labels)";
    return limit;
  }
  const std::optional<double> object_m = object_distance_m(frame, risk.unknown_object_min_area_m2);
  if (object_m) {
    limit.set_by = speed_limit_t::SET_BY_UNKNOWN_OBJECT;
    limit.separation_m = *object_m;
    limit.max_arm_speed_m_s = highest_arm_speed_for_separation_m_s(risk, response_time_s, *object_m);
    limit.reason = "unknown object " + fixed(*object_m, 2) + " m from the arm: S fits up to " +
                   fixed(limit.max_arm_speed_m_s, 2) + " m/s";
  } else {
    const double range_m = field_range_m(frame);
    limit.set_by = speed_limit_t::SET_BY_RANGE;
    limit.max_arm_speed_m_s = highest_arm_speed_for_separation_m_s(risk, response_time_s, range_m);
    limit.reason = "nothing unexplained within the " + fixed(range_m, 2) + " m monitored: S fits up to " +
                   fixed(limit.max_arm_speed_m_s, 2) + " m/s";
  }
  limit_by_body_regions(risk, response_time_s, frame, rules, &limit);
  return limit;
}

speed_limit_t stand_still_limit(const RiskSettings& risk, int64_t utime, const std::string& camera_id,
                                const std::string& reason) {
  speed_limit_t limit = limit_base(risk, utime, -1, camera_id);
  limit.reason = "stand: " + reason;
  return limit;
}

}  // namespace tofguard::risk
