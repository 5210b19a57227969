#include "tofguard/risk/decision_rule.hpp"

#include <algorithm>
#include <string>

namespace tofguard::risk {
namespace {

// A verdict of `level` with `finding`'s cause, suspect, score and threshold.
risk_t verdict(int64_t utime, int64_t seq, int8_t level, const FrameFinding& finding,
               const std::string& detail) {
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

DecisionRule::DecisionRule(const RiskSettings& risk)
    : debounce_frames_(risk.debounce_frames), sensor_debounce_frames_(risk.sensor_debounce_frames) {}

risk_t DecisionRule::decide(const discrepancy_t& frame, FrameFinding finding,
                            const std::optional<FrameFinding>& expired_input) {
  consecutive_ = finding.cause == risk_t::CAUSE_NONE ? 0 : consecutive_ + 1;
  if (expired_input) {
    return verdict(frame.utime, frame.seq, risk_t::DANGEROUS, *expired_input,
                   "timeout: " + expired_input->detail);
  }
  if (finding.cause == risk_t::CAUSE_NONE) {
    finding.score = frame.mismatch_fraction;
    return verdict(frame.utime, frame.seq, risk_t::SAFE, finding,
                   "model and camera agree (mismatch fraction): " +
                       std::to_string(frame.num_compared - frame.num_match) + " of " +
                       std::to_string(frame.num_compared) + " compared pixels differ");
  }
  const int needed = is_fault_cause(finding.cause) ? sensor_debounce_frames_ : debounce_frames_;
  return verdict(frame.utime, frame.seq, consecutive_ >= needed ? risk_t::DANGEROUS : risk_t::WARNING,
                 finding,
                 finding.detail + " [" + std::to_string(std::min(consecutive_, needed)) + "/" +
                     std::to_string(needed) + " frames]");
}

risk_t timeout_verdict(int64_t last_frame_utime, const FrameFinding& expired_input) {
  return verdict(last_frame_utime, -1, risk_t::DANGEROUS, expired_input, "timeout: " + expired_input.detail);
}

}  // namespace tofguard::risk
