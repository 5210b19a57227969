#pragma once
// The plan rule (docs/safety-chain.md, "The plan"): the arm controller's
// plan (PLANNED_TRAJECTORY) against the joint state of a frame's capture
// time. A joint further than risk.plan.max_deviation_deg (prismatic:
// max_deviation_m) from the plan at the joint state's utime is "the arm
// left its plan": cause UNCLASSIFIED, suspect the joint furthest off
// relative to its limit, score and threshold in degrees (mm).
#include <optional>
#include <set>
#include <string>

#include "tofguard/common/planned_trajectory.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

class PlanMonitor {
 public:
  // risk.plan; `prismatic_joints` (positions in metres, all others radians).
  PlanMonitor(const RiskSettings& risk, std::set<std::string> prismatic_joints);

  // A plan that passed check_planned_trajectory and the joint-name check.
  void on_plan(const planned_trajectory_t& plan) { plan_.add(plan); }

  // The finding for `state` (the joint state at a frame's capture time);
  // nothing when the rule is off, the state's utime lies outside the plan's
  // span (no plan, or past its end), or every joint is within its limit.
  std::optional<FrameFinding> deviation(const joint_state_t& state) const;

 private:
  bool enabled_;
  double max_deviation_rad_;
  double max_deviation_m_;
  std::set<std::string> prismatic_joints_;
  PlannedTrajectory plan_;
};

}  // namespace tofguard::risk
