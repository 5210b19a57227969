#pragma once
// tofguard-risk's decision rule (docs/safety-chain.md, "Levels and
// debounce"): a frame's final finding becomes a risk_t level. A finding is
// WARNING until findings have held for risk.debounce_frames consecutive
// frames (risk.sensor_debounce_frames for sensor and component faults), then
// DANGEROUS; one clean frame resets the count. An expired input deadline
// makes the frame DANGEROUS at once (the deadline is its debounce).
#include <cstdint>
#include <optional>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/risk/risk_settings.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::risk {

class DecisionRule {
 public:
  explicit DecisionRule(const RiskSettings& risk);

  // The verdict on `frame` (its utime and seq) whose findings are final
  // (rules, estimate and plan applied), judged in frame order: every call
  // counts one frame for the debounce, also while `expired_input` (the first
  // expired deadline) overrides the verdict.
  risk_t decide(const discrepancy_t& frame, FrameFinding finding,
                const std::optional<FrameFinding>& expired_input);

  // Consecutive frames with a finding so far.
  int consecutive_findings() const { return consecutive_; }

 private:
  int debounce_frames_;
  int sensor_debounce_frames_;
  int consecutive_ = 0;
};

// The timeout verdict of an expired deadline: DANGEROUS, seq -1 (no frame),
// utime of the last judged frame.
risk_t timeout_verdict(int64_t last_frame_utime, const FrameFinding& expired_input);

}  // namespace tofguard::risk
