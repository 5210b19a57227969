#include "tofguard/risk/input_deadlines.hpp"

#include <vector>

#include "tofguard/risk_t.hpp"

namespace tofguard::risk {
InputDeadlines::InputDeadlines(const RiskSettings& risk, const ChannelNames& channels, int64_t start_us)
    : depth_{channels.depth, risk_t::CAUSE_SENSOR_FAULT, risk.depth_deadline_us, start_us},
      joint_state_{channels.joint_state, risk_t::CAUSE_SENSOR_FAULT, risk.joint_state_deadline_us, start_us},
      camera_pose_{channels.camera_pose, risk_t::CAUSE_SENSOR_FAULT, risk.camera_pose_deadline_us, start_us},
      camera_pose_required_(risk.camera_pose_required),
      discrepancy_{channels.discrepancy, risk_t::CAUSE_COMPONENT_FAULT, risk.discrepancy_deadline_us,
                   start_us} {
  for (const std::string& process : risk.required_heartbeats) {
    heartbeats_[process] =
        Deadline{process,           risk_t::CAUSE_COMPONENT_FAULT, risk.heartbeat_deadline_us, start_us,
                 /*ever=*/false,
                 /*heartbeat=*/true};
  }
}

void InputDeadlines::touch(Deadline* d, int64_t now_us) {
  d->last_us = now_us;
  d->ever = true;
}

void InputDeadlines::on_heartbeat(const std::string& process, int64_t now_us) {
  const auto it = heartbeats_.find(process);
  if (it != heartbeats_.end()) touch(&it->second, now_us);
}

std::optional<FrameFinding> InputDeadlines::first_expired(int64_t now_us) const {
  std::vector<const Deadline*> order = {&depth_, &joint_state_};
  if (camera_pose_required_) order.push_back(&camera_pose_);
  for (const auto& [name, d] : heartbeats_) order.push_back(&d);
  // Last: a silent discrepancy stream while the camera is fresh means the
  // comparison itself has stopped.
  order.push_back(&discrepancy_);
  for (const Deadline* d : order) {
    const int64_t age_us = now_us - d->last_us;
    if (age_us <= d->limit_us) continue;
    FrameFinding f;
    f.cause = d->cause;
    f.suspect = d->what;
    f.score = static_cast<double>(age_us) / 1000.0;
    f.threshold = static_cast<double>(d->limit_us) / 1000.0;
    f.detail = d->what + (d->heartbeat ? " heartbeat" : "") +
               " stale (age ms): " + (d->ever ? "nothing for " : "nothing since start, ") +
               std::to_string(age_us / 1000) + " ms, deadline " + std::to_string(d->limit_us / 1000) + " ms";
    return f;
  }
  return std::nullopt;
}

}  // namespace tofguard::risk
