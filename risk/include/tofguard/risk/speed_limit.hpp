#pragma once
// The speed limit tofguard-risk gives the arm's controller with every frame
// (speed_limit_t on SAFETY_SPEED_LIMIT, docs/safety-chain.md, "Protective
// fields"): speed and separation monitoring with speed scaling. The
// protective field stops an arm whose S (risk/protective_field.hpp) no
// longer fits the separation to the nearest unexplained surface; the limit
// is the arm speed at which it still fits, so a controller that keeps below
// it slows as a person comes near instead of being stopped. With nothing
// unexplained within the range monitored, the range sets it.
//
// Units: m/s, metres, milliseconds. Pure logic: no LCM, no clocks.
#include <cstdint>
#include <string>
#include <vector>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/risk/body_region_rules.hpp"
#include "tofguard/settings/risk_settings.hpp"
#include "tofguard/speed_limit_t.hpp"

namespace tofguard::risk {

// The frame's limit: for an unusable frame, or one without the arm's cover
// (field_available false), 0 (SET_BY_NO_JUDGEMENT); else the highest arm
// speed whose S fits the distance to the nearest unexplained surface of
// unknown_object_min_area_m2 (SET_BY_UNKNOWN_OBJECT), or the range
// monitored when there is none (SET_BY_RANGE). `arm_speed_m_s`: the arm's
// speed bound at the frame (+infinity when it cannot be bounded, sent as
// -1). valid_for_ms: risk.deadlines_ms.discrepancy.
//
// With the occupant's rules (body_region_rules.hpp; empty: no occupant),
// each region of the frame (discrepancy_t.body_region) limits it too, at
// its separation less its envelope, the arm's position uncertain by
// sin(risk.evidence.joint_offset) times the frame's largest joint reach (an
// undetected offset of one joint, docs/safety-chain.md, "The user"); the
// lowest limit wins (SET_BY_BODY_REGION when a region's). A frame that
// lacks a region the rules have is 0 (SET_BY_NO_JUDGEMENT): the renderer
// that placed the arm does not know the user.
speed_limit_t frame_speed_limit(const RiskSettings& risk, double response_time_s, const discrepancy_t& frame,
                                double arm_speed_m_s, const std::vector<BodyRegionRule>& rules = {});

// 0 m/s for a deadline that expired (seq -1, SET_BY_NO_JUDGEMENT), with
// the timeout's utime (the last frame's) and reason.
speed_limit_t stand_still_limit(const RiskSettings& risk, int64_t utime, const std::string& camera_id,
                                const std::string& reason);

}  // namespace tofguard::risk
