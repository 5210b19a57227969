#include "tofguard/risk/estimate_gate.hpp"

#include <algorithm>
#include <cmath>

#include "tofguard/risk/estimate_finding.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::risk {
namespace {

// Estimates kept for frames still to come or waiting, and frames remembered
// for counting late estimates.
constexpr size_t kKeptEstimates = 16;
constexpr size_t kKeptMissedSeqs = 64;

}  // namespace

EstimateGate::EstimateGate(const RiskSettings& risk, std::set<std::string> prismatic_joints)
    : risk_(risk),
      prismatic_joints_(std::move(prismatic_joints)),
      enabled_(risk.estimate_enabled),
      wait_us_(risk.estimate_wait_us),
      max_age_us_(risk.estimate_max_age_us) {}

std::vector<ClassifiedFrame> EstimateGate::admit(ClassifiedFrame frame, int64_t now_us) {
  waiting_.push_back(WaitingFrame{std::move(frame), now_us + wait_us_});
  return release(now_us);
}

std::vector<ClassifiedFrame> EstimateGate::add_estimate(const motion_estimate_t& estimate, int64_t now_us) {
  stats_.received++;
  if (std::find(missed_seqs_.begin(), missed_seqs_.end(), estimate.seq) != missed_seqs_.end()) stats_.late++;
  estimates_.push_back(estimate);
  while (estimates_.size() > kKeptEstimates) estimates_.pop_front();
  return release(now_us);
}

std::vector<ClassifiedFrame> EstimateGate::release_due(int64_t now_us) { return release(now_us); }

const motion_estimate_t* EstimateGate::estimate_for(const discrepancy_t& frame, bool or_older) const {
  for (auto it = estimates_.rbegin(); it != estimates_.rend(); ++it) {
    if (it->seq == frame.seq && it->utime == frame.utime && it->camera_id == frame.camera_id) return &*it;
  }
  if (!or_older) return nullptr;
  // Else the newest of an earlier frame within max_age (camera utimes).
  const motion_estimate_t* newest = nullptr;
  for (const motion_estimate_t& e : estimates_) {
    if (e.camera_id != frame.camera_id || e.utime > frame.utime || frame.utime - e.utime > max_age_us_)
      continue;
    if (!newest || e.utime > newest->utime) newest = &e;
  }
  return newest;
}

std::vector<ClassifiedFrame> EstimateGate::release(int64_t now_us) {
  std::vector<ClassifiedFrame> out;
  while (!waiting_.empty()) {
    WaitingFrame& head = waiting_.front();
    const bool wants = waits(head.classified);
    const bool has_own = estimate_for(head.classified.frame, /*or_older=*/false) != nullptr;
    if (wants && !has_own && now_us < head.wait_until_us) break;
    if (wants && !has_own) {
      stats_.missing++;
      missed_seqs_.push_back(head.classified.frame.seq);
      while (missed_seqs_.size() > kKeptMissedSeqs) missed_seqs_.pop_front();
    }
    if (wants) rename_cause(&head.classified);
    out.push_back(std::move(head.classified));
    waiting_.pop_front();
  }
  return out;
}

void EstimateGate::rename_cause(ClassifiedFrame* c) {
  const discrepancy_t& frame = c->frame;
  FrameFinding& finding = c->finding;
  const motion_estimate_t* estimate = estimate_for(frame, /*or_older=*/true);
  if (estimate == nullptr) {
    finding.detail += " (no motion estimate within " + fixed(risk_.estimate_wait_us / 1000.0, 0) + " ms)";
    return;
  }
  EstimateContext context;
  context.prismatic_joints = prismatic_joints_;
  context.near_arm_evidence = frame.near_arm_area_m2 >= risk_.unknown_object_min_area_m2;
  FrameFinding refined = classify_estimate(*estimate, risk_, context);
  // An earlier frame's estimate is evidence only of what it names (a joint
  // or the camera): that it explained nothing says nothing about this frame,
  // which may show a fault that began after it.
  const bool own = estimate->seq == frame.seq;
  if (!own && refined.cause != risk_t::CAUSE_JOINT_ERROR &&
      refined.cause != risk_t::CAUSE_CALIBRATION_ERROR) {
    refined = FrameFinding{};
  }
  if (refined.cause != risk_t::CAUSE_NONE) {
    stats_.used++;
    if (!own) {
      refined.detail += " (estimate of frame " + std::to_string(estimate->seq) + ", " +
                        fixed((frame.utime - estimate->utime) / 1000.0, 0) + " ms earlier)";
    }
    finding = std::move(refined);
  } else {
    stats_.explained_nothing++;
    finding.detail +=
        " (estimate explains nothing: " +
        (estimate->usable ? std::string(estimate->converged ? "no significant offset" : "not converged")
                          : "unusable, " + estimate->unusable_reason) +
        ")";
  }
}

}  // namespace tofguard::risk
