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
    : debounce_frames_(risk.debounce_frames),
      sensor_debounce_frames_(risk.sensor_debounce_frames),
      clear_frames_(std::max(1, risk.evidence_clear_frames)) {}

risk_t DecisionRule::decide(const discrepancy_t& frame, FrameFinding finding,
                            const std::optional<FrameFinding>& expired_input, bool evidence_quiet,
                            const std::string& evidence_summary) {
  consecutive_ = finding.cause == risk_t::CAUSE_NONE ? 0 : consecutive_ + 1;
  if (open_) {
    const bool clean = finding.cause == risk_t::CAUSE_NONE && evidence_quiet && !expired_input;
    clean_frames_ = clean ? clean_frames_ + 1 : 0;
    if (clean_frames_ >= clear_frames_) {
      open_.reset();
      clean_frames_ = 0;
    }
  }
  if (expired_input) {
    return verdict(frame.utime, frame.seq, risk_t::DANGEROUS, *expired_input,
                   "timeout: " + expired_input->detail);
  }
  if (open_) {
    // The diagnosis stays as it was at the stop: same cause and suspect.
    std::string now = finding.cause == risk_t::CAUSE_NONE ? std::string("no finding") : finding.detail;
    if (!evidence_summary.empty()) now += "; " + evidence_summary;
    return verdict(frame.utime, frame.seq, risk_t::DANGEROUS, open_->finding,
                   "diagnosis open since seq " + std::to_string(open_->seq) + ": " + open_->finding.detail +
                       "; this frame: " + now + " [clean " + std::to_string(clean_frames_) + "/" +
                       std::to_string(clear_frames_) + " frames]");
  }
  if (finding.cause == risk_t::CAUSE_NONE) {
    finding.score = frame.mismatch_fraction;
    return verdict(frame.utime, frame.seq, risk_t::SAFE, finding,
                   "model and camera agree (mismatch fraction): " +
                       std::to_string(frame.num_compared - frame.num_match) + " of " +
                       std::to_string(frame.num_compared) + " compared pixels differ");
  }
  int8_t level = risk_t::WARNING;
  std::string detail = finding.detail;
  if (finding.at_once) {
    level = risk_t::DANGEROUS;
  } else if (!finding.warning_only) {
    const int needed = is_fault_cause(finding.cause) ? sensor_debounce_frames_ : debounce_frames_;
    level = consecutive_ >= needed ? risk_t::DANGEROUS : risk_t::WARNING;
    detail +=
        " [" + std::to_string(std::min(consecutive_, needed)) + "/" + std::to_string(needed) + " frames]";
  }
  const risk_t r = verdict(frame.utime, frame.seq, level, finding, detail);
  if (level == risk_t::DANGEROUS) {
    open_ = Diagnosis{finding, frame.seq};
    open_->finding.detail = detail;
    clean_frames_ = 0;
  }
  return r;
}

risk_t timeout_verdict(int64_t last_frame_utime, const FrameFinding& expired_input) {
  return verdict(last_frame_utime, -1, risk_t::DANGEROUS, expired_input, "timeout: " + expired_input.detail);
}

}  // namespace tofguard::risk
