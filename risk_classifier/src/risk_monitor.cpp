#include "risk_monitor.hpp"

#include <algorithm>
#include <cmath>

namespace tofguard::risk {
namespace {

int64_t ms_to_us(double ms) { return static_cast<int64_t>(std::llround(ms * 1000.0)); }

}  // namespace

RiskMonitor::RiskMonitor(const Config& config, RobotTree robot, int64_t start_us)
    : config_(config),
      robot_(std::move(robot)),
      depth_{config.channels.depth, risk_t::CAUSE_SENSOR_FAULT, ms_to_us(config.risk.depth_deadline_ms), start_us},
      discrepancy_{config.channels.discrepancy, risk_t::CAUSE_COMPONENT_FAULT,
                   ms_to_us(config.risk.discrepancy_deadline_ms), start_us},
      joint_state_{config.channels.joint_state, risk_t::CAUSE_SENSOR_FAULT,
                   ms_to_us(config.risk.joint_state_deadline_ms), start_us},
      camera_pose_{config.channels.camera_pose, risk_t::CAUSE_SENSOR_FAULT,
                   ms_to_us(config.risk.camera_pose_deadline_ms), start_us} {
  for (const std::string& process : config.risk.required_heartbeats) {
    heartbeats_[process] =
        Deadline{process, risk_t::CAUSE_COMPONENT_FAULT, ms_to_us(config.risk.heartbeat_deadline_ms), start_us};
  }
}

void RiskMonitor::touch(Deadline* d, int64_t now_us) {
  d->last_us = now_us;
  d->ever = true;
}

void RiskMonitor::on_depth(int64_t now_us) { touch(&depth_, now_us); }

void RiskMonitor::on_joint_state(const joint_state_t& state, int64_t now_us) {
  touch(&joint_state_, now_us);
  double fastest = 0;
  for (double v : state.velocity) fastest = std::max(fastest, std::abs(v));
  if (!arm_moving_by_utime_.empty() && state.utime < arm_moving_by_utime_.back().first) return;  // out of order
  arm_moving_by_utime_.emplace_back(state.utime, fastest >= config_.risk.moving_joint_speed_rad_s);
  while (arm_moving_by_utime_.front().first < state.utime - 2'000'000) arm_moving_by_utime_.pop_front();
}

bool RiskMonitor::arm_moving_at(int64_t utime) const {
  // The newest joint state taken at or before `utime`; for a frame older
  // than all of them, the oldest.
  for (auto it = arm_moving_by_utime_.rbegin(); it != arm_moving_by_utime_.rend(); ++it) {
    if (it->first <= utime) return it->second;
  }
  return !arm_moving_by_utime_.empty() && arm_moving_by_utime_.front().second;
}

void RiskMonitor::on_camera_pose(int64_t now_us) { touch(&camera_pose_, now_us); }

void RiskMonitor::on_heartbeat(const heartbeat_t& heartbeat, int64_t now_us) {
  const auto it = heartbeats_.find(heartbeat.process);
  if (it != heartbeats_.end()) touch(&it->second, now_us);
}

std::string RiskMonitor::check_joint_names(const joint_state_t& state) const {
  for (int i = 0; i < state.num_joints; ++i) {
    if (!robot_.is_movable_joint(state.name[i])) {
      return "name[" + std::to_string(i) + "]: expected a moving joint of the robot's URDF, got '" +
             state.name[i] + "'";
    }
  }
  return "";
}

std::optional<FrameFinding> RiskMonitor::expired(int64_t now_us) const {
  std::vector<const Deadline*> order = {&depth_, &joint_state_};
  if (config_.risk.camera_pose_required) order.push_back(&camera_pose_);
  for (const auto& [name, d] : heartbeats_) order.push_back(&d);
  // Last: a silent discrepancy stream while the camera is fresh means the
  // comparison itself has stopped.
  order.push_back(&discrepancy_);
  for (const Deadline* d : order) {
    const int64_t age_us = now_us - d->last_us;
    if (age_us <= d->limit_us) continue;
    const bool heartbeat = heartbeats_.count(d->what) > 0;
    FrameFinding f;
    f.cause = d->cause;
    f.suspect = d->what;
    f.score = static_cast<double>(age_us) / 1000.0;
    f.threshold = static_cast<double>(d->limit_us) / 1000.0;
    f.detail = d->what + (heartbeat ? " heartbeat" : "") + " stale (age ms): " +
               (d->ever ? "nothing for " : "nothing since start, ") + std::to_string(age_us / 1000) +
               " ms, deadline " + std::to_string(d->limit_us / 1000) + " ms";
    return f;
  }
  return std::nullopt;
}

namespace {

// A verdict of `level` with `finding`'s cause, suspect, score and detail.
risk_t verdict(int64_t utime, int64_t seq, int8_t level, const FrameFinding& finding, const std::string& detail) {
  risk_t r;
  r.utime = utime;
  r.seq = seq;
  r.level = level;
  r.cause = finding.cause;
  r.suspect = finding.suspect;
  r.score = finding.score;
  r.threshold = finding.threshold;
  r.detail = detail;
  return r;
}

}  // namespace

std::optional<risk_t> RiskMonitor::check_deadlines(int64_t now_us) const {
  const std::optional<FrameFinding> f = expired(now_us);
  if (!f) return std::nullopt;
  return verdict(last_frame_utime_, -1, risk_t::DANGEROUS, *f, "timeout: " + f->detail);
}

risk_t RiskMonitor::on_discrepancy(const discrepancy_t& frame, int64_t now_us) {
  touch(&discrepancy_, now_us);
  last_frame_utime_ = frame.utime;

  ClassifierContext context;
  context.depth_channel = config_.channels.depth;
  context.labels_channel = config_.channels.labels;
  context.arm_moving = arm_moving_at(frame.utime);
  FrameFinding finding = classify_frame(frame, robot_, config_.risk, context);
  consecutive_ = finding.cause == risk_t::CAUSE_NONE ? 0 : consecutive_ + 1;

  if (const std::optional<FrameFinding> stale = expired(now_us)) {
    return verdict(frame.utime, frame.seq, risk_t::DANGEROUS, *stale, "timeout: " + stale->detail);
  }
  if (finding.cause == risk_t::CAUSE_NONE) {
    finding.score = frame.mismatch_fraction;
    return verdict(frame.utime, frame.seq, risk_t::SAFE, finding,
                   "model and camera agree (mismatch fraction): " + std::to_string(frame.num_compared - frame.num_match) +
                       " of " + std::to_string(frame.num_compared) + " compared pixels differ");
  }
  const int needed = is_fault_cause(finding.cause) ? config_.risk.sensor_debounce_frames : config_.risk.debounce_frames;
  return verdict(frame.utime, frame.seq, consecutive_ >= needed ? risk_t::DANGEROUS : risk_t::WARNING, finding,
                 finding.detail + " [" + std::to_string(std::min(consecutive_, needed)) + "/" +
                     std::to_string(needed) + " frames]");
}

}  // namespace tofguard::risk
