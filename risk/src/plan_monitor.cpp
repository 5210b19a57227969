#include "tofguard/risk/plan_monitor.hpp"

#include <cmath>

#include "tofguard/risk_t.hpp"

namespace tofguard::risk {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

}  // namespace

PlanMonitor::PlanMonitor(const RiskSettings& risk, std::set<std::string> prismatic_joints)
    : enabled_(risk.plan_enabled),
      max_deviation_rad_(risk.plan_max_deviation_deg / kRadToDeg),
      max_deviation_m_(risk.plan_max_deviation_m),
      prismatic_joints_(std::move(prismatic_joints)) {}

std::optional<FrameFinding> PlanMonitor::deviation(const joint_state_t& state) const {
  if (!enabled_) return std::nullopt;
  const auto planned = plan_.at(state.utime);
  if (!planned) return std::nullopt;  // outside the plan's time span: nothing to compare
  std::optional<FrameFinding> worst;
  double worst_ratio = 0;
  for (int i = 0; i < state.num_joints; ++i) {
    const auto p = planned->find(state.name[i]);
    if (p == planned->end()) continue;
    const bool prismatic = prismatic_joints_.count(state.name[i]) > 0;
    const double deviation = std::abs(state.position[i] - p->second);
    const double limit = prismatic ? max_deviation_m_ : max_deviation_rad_;
    if (!(deviation > limit) || deviation / limit <= worst_ratio) continue;
    worst_ratio = deviation / limit;
    // Reported in degrees (revolute) or millimetres (prismatic).
    const double scale = prismatic ? 1000.0 : kRadToDeg;
    const std::string unit = prismatic ? " mm" : "°";
    FrameFinding f;
    f.cause = risk_t::CAUSE_UNCLASSIFIED;
    f.suspect = state.name[i];
    f.score = deviation * scale;
    f.threshold = limit * scale;
    f.detail = "arm left its plan (" + std::string(prismatic ? "mm" : "deg") + "): " + state.name[i] +
               " is " + fixed(deviation * scale, 1) + unit + " from the plan (limit " +
               fixed(limit * scale, 1) + unit + ")";
    worst = f;
  }
  return worst;
}

}  // namespace tofguard::risk
