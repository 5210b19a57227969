#include "tofguard/risk/risk_monitor.hpp"

#include <algorithm>
#include <cmath>

#include "tofguard/risk/estimate_finding.hpp"

namespace tofguard::risk {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
// Estimates kept for frames still to come or waiting, and judged frames
// remembered for counting late estimates.
constexpr size_t kKeptEstimates = 16;
constexpr size_t kKeptJudgedSeqs = 64;

}  // namespace

RiskMonitor::RiskMonitor(const RiskSettings& settings, const ChannelNames& channels, RobotTree robot,
                         int64_t start_us)
    : settings_(settings),
      channels_(channels),
      robot_(std::move(robot)),
      depth_{channels.depth, risk_t::CAUSE_SENSOR_FAULT, settings.depth_deadline_us, start_us},
      discrepancy_{channels.discrepancy, risk_t::CAUSE_COMPONENT_FAULT,
                   settings.discrepancy_deadline_us, start_us},
      joint_state_{channels.joint_state, risk_t::CAUSE_SENSOR_FAULT,
                   settings.joint_state_deadline_us, start_us},
      camera_pose_{channels.camera_pose, risk_t::CAUSE_SENSOR_FAULT,
                   settings.camera_pose_deadline_us, start_us} {
  for (const std::string& process : settings.required_heartbeats) {
    heartbeats_[process] =
        Deadline{process, risk_t::CAUSE_COMPONENT_FAULT, settings.heartbeat_deadline_us, start_us};
  }
}

void RiskMonitor::touch(Deadline* d, int64_t now_us) {
  d->last_us = now_us;
  d->ever = true;
}

void RiskMonitor::on_depth(int64_t now_us) { touch(&depth_, now_us); }

void RiskMonitor::on_joint_state(const joint_state_t& state, int64_t now_us) {
  touch(&joint_state_, now_us);
  // Out-of-order joint states are not added to the by-utime record.
  if (joint_states_by_utime_.empty() || state.utime >= joint_states_by_utime_.back().utime) {
    joint_states_by_utime_.push_back(state);
    while (joint_states_by_utime_.front().utime < state.utime - 2'000'000) joint_states_by_utime_.pop_front();
  }
}

void RiskMonitor::on_plan(const planned_trajectory_t& plan) { plan_.add(plan); }

const joint_state_t* RiskMonitor::joint_state_at(int64_t utime) const {
  // The newest joint state taken at or before `utime`; for a frame older
  // than all of them, the oldest.
  for (auto it = joint_states_by_utime_.rbegin(); it != joint_states_by_utime_.rend(); ++it) {
    if (it->utime <= utime) return &*it;
  }
  return joint_states_by_utime_.empty() ? nullptr : &joint_states_by_utime_.front();
}

std::optional<FrameFinding> RiskMonitor::plan_deviation_at(int64_t utime) const {
  if (!settings_.plan_enabled) return std::nullopt;
  const joint_state_t* found = joint_state_at(utime);
  if (found == nullptr) return std::nullopt;
  const joint_state_t& state = *found;
  const auto planned = plan_.at(state.utime);
  if (!planned) return std::nullopt;  // outside the plan's time span: nothing to compare
  const RiskSettings& r = settings_;
  std::optional<FrameFinding> deviation_finding;
  double worst_ratio = 0;
  for (int i = 0; i < state.num_joints; ++i) {
    const auto p = planned->find(state.name[i]);
    if (p == planned->end()) continue;
    const bool prismatic = robot_.prismatic_joints().count(state.name[i]) > 0;
    const double deviation = std::abs(state.position[i] - p->second);
    const double limit = prismatic ? r.plan_max_deviation_m : r.plan_max_deviation_deg / kRadToDeg;
    if (!(deviation > limit) || deviation / limit <= worst_ratio) continue;
    worst_ratio = deviation / limit;
    const double scale = prismatic ? 1000.0 : kRadToDeg;
    const std::string unit = prismatic ? " mm" : "°";
    FrameFinding f;
    f.cause = risk_t::CAUSE_UNCLASSIFIED;
    f.suspect = state.name[i];
    f.score = deviation * scale;
    f.threshold = limit * scale;
    f.detail = "arm left its plan (" + std::string(prismatic ? "mm" : "deg") + "): " + state.name[i] + " is " +
               fixed(deviation * scale, 1) + unit + " from the plan (limit " + fixed(limit * scale, 1) + unit + ")";
    deviation_finding = f;
  }
  return deviation_finding;
}

bool RiskMonitor::arm_moving_at(int64_t utime) const {
  const joint_state_t* state = joint_state_at(utime);
  if (state == nullptr) return false;
  double fastest = 0;
  for (double v : state->velocity) fastest = std::max(fastest, std::abs(v));
  return fastest >= settings_.moving_joint_speed_rad_s;
}

void RiskMonitor::on_camera_pose(int64_t now_us) { touch(&camera_pose_, now_us); }

void RiskMonitor::on_heartbeat(const heartbeat_t& heartbeat, int64_t now_us) {
  const auto it = heartbeats_.find(heartbeat.process);
  if (it != heartbeats_.end()) touch(&it->second, now_us);
}

std::string RiskMonitor::check_joint_names(const std::vector<std::string>& names, const std::string& field) const {
  for (size_t i = 0; i < names.size(); ++i) {
    if (!robot_.is_movable_joint(names[i])) {
      return field + "[" + std::to_string(i) + "]: expected a moving joint of the robot's URDF, got '" + names[i] +
             "'";
    }
  }
  return "";
}

std::optional<FrameFinding> RiskMonitor::expired(int64_t now_us) const {
  std::vector<const Deadline*> order = {&depth_, &joint_state_};
  if (settings_.camera_pose_required) order.push_back(&camera_pose_);
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

FrameFinding RiskMonitor::discrepancy_finding(const discrepancy_t& frame) const {
  ClassifierContext context;
  context.depth_channel = channels_.depth;
  context.labels_channel = channels_.labels;
  context.arm_moving = arm_moving_at(frame.utime);
  return classify_frame(frame, robot_, settings_, context);
}

bool RiskMonitor::wants_estimate(const discrepancy_t& frame) const {
  return settings_.estimate_enabled && is_model_mismatch(discrepancy_finding(frame).cause);
}

const motion_estimate_t* RiskMonitor::estimate_for(const discrepancy_t& frame, bool or_older) const {
  for (auto it = estimates_.rbegin(); it != estimates_.rend(); ++it) {
    if (it->seq == frame.seq && it->utime == frame.utime && it->camera_id == frame.camera_id) return &*it;
  }
  if (!or_older) return nullptr;
  // Else the newest of an earlier frame within max_age (camera utimes).
  const motion_estimate_t* newest = nullptr;
  const int64_t max_age_us = settings_.estimate_max_age_us;
  for (const motion_estimate_t& e : estimates_) {
    if (e.camera_id != frame.camera_id || e.utime > frame.utime || frame.utime - e.utime > max_age_us) continue;
    if (!newest || e.utime > newest->utime) newest = &e;
  }
  return newest;
}

risk_t RiskMonitor::on_discrepancy(const discrepancy_t& frame, int64_t now_us) {
  touch(&discrepancy_, now_us);
  return judge(frame, now_us, /*waited=*/false);
}

std::vector<risk_t> RiskMonitor::on_frame(const discrepancy_t& frame, int64_t now_us) {
  touch(&discrepancy_, now_us);
  WaitingFrame w;
  w.frame = frame;
  w.wants_estimate = wants_estimate(frame);
  w.wait_until_us = now_us + settings_.estimate_wait_us;
  waiting_.push_back(std::move(w));
  return release(now_us);
}

std::vector<risk_t> RiskMonitor::on_estimate(const motion_estimate_t& estimate, int64_t now_us) {
  estimate_stats_.received++;
  if (std::find(judged_seqs_.begin(), judged_seqs_.end(), estimate.seq) != judged_seqs_.end()) {
    estimate_stats_.late++;
  }
  estimates_.push_back(estimate);
  while (estimates_.size() > kKeptEstimates) estimates_.pop_front();
  return release(now_us);
}

std::vector<risk_t> RiskMonitor::release_due(int64_t now_us) { return release(now_us); }

std::vector<risk_t> RiskMonitor::release(int64_t now_us) {
  std::vector<risk_t> out;
  while (!waiting_.empty()) {
    const WaitingFrame& head = waiting_.front();
    const bool has_estimate = estimate_for(head.frame, /*or_older=*/false) != nullptr;
    if (head.wants_estimate && !has_estimate && now_us < head.wait_until_us) break;
    if (head.wants_estimate && !has_estimate) {
      estimate_stats_.missing++;
      judged_seqs_.push_back(head.frame.seq);
      while (judged_seqs_.size() > kKeptJudgedSeqs) judged_seqs_.pop_front();
    }
    out.push_back(judge(head.frame, now_us, head.wants_estimate));
    waiting_.pop_front();
  }
  return out;
}

risk_t RiskMonitor::judge(const discrepancy_t& frame, int64_t now_us, bool waited) {
  last_frame_utime_ = frame.utime;
  FrameFinding finding = discrepancy_finding(frame);
  // The estimate refines a model mismatch (fail safe: it replaces one
  // finding by another, never by "safe"; without one the discrepancy rules
  // stand).
  if (settings_.estimate_enabled && is_model_mismatch(finding.cause)) {
    if (const motion_estimate_t* estimate = estimate_for(frame, /*or_older=*/true)) {
      EstimateContext context;
      context.prismatic_joints = robot_.prismatic_joints();
      context.near_arm_evidence = frame.near_arm_area_m2 >= settings_.unknown_object_min_area_m2;
      FrameFinding refined = classify_estimate(*estimate, settings_, context);
      // An earlier frame's estimate is evidence only of what it names (a
      // joint or the camera): that it explained nothing says nothing about
      // this frame, which may show a fault that began after it.
      const bool own = estimate->seq == frame.seq;
      if (!own && refined.cause != risk_t::CAUSE_JOINT_ERROR && refined.cause != risk_t::CAUSE_CALIBRATION_ERROR) {
        refined = FrameFinding{};
      }
      if (refined.cause != risk_t::CAUSE_NONE) {
        estimate_stats_.used++;
        if (!own) {
          refined.detail += " (estimate of frame " + std::to_string(estimate->seq) + ", " +
                            fixed((frame.utime - estimate->utime) / 1000.0, 0) + " ms earlier)";
        }
        finding = std::move(refined);
      } else {
        estimate_stats_.explained_nothing++;
        finding.detail += " (estimate explains nothing: " +
                          (estimate->usable ? std::string(estimate->converged ? "no significant offset" : "not converged")
                                            : "unusable, " + estimate->unusable_reason) +
                          ")";
      }
    } else if (waited) {
      finding.detail += " (no motion estimate within " + fixed(settings_.estimate_wait_us / 1000.0, 0) + " ms)";
    }
  }
  // The arm left its plan: only when nothing else is wrong with the frame.
  // (The joint state at the frame's capture time: a replayed log is judged
  // the same on every run however late the frame is processed.)
  if (finding.cause == risk_t::CAUSE_NONE) {
    if (std::optional<FrameFinding> deviation = plan_deviation_at(frame.utime)) finding = std::move(*deviation);
  }
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
  const int needed = is_fault_cause(finding.cause) ? settings_.sensor_debounce_frames : settings_.debounce_frames;
  return verdict(frame.utime, frame.seq, consecutive_ >= needed ? risk_t::DANGEROUS : risk_t::WARNING, finding,
                 finding.detail + " [" + std::to_string(std::min(consecutive_, needed)) + "/" +
                     std::to_string(needed) + " frames]");
}

}  // namespace tofguard::risk
