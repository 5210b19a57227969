#pragma once
// tofguard-risk's decision rule (docs/safety-chain.md, "Levels and
// debounce"): a frame's final finding becomes a risk_t level. A finding is
// WARNING until findings have held for risk.debounce_frames consecutive
// frames (risk.sensor_debounce_frames for sensor and component faults), then
// DANGEROUS; one clean frame resets the count. A sequential test that
// crossed (FrameFinding::at_once) is DANGEROUS at once; one whose evidence
// grows (warning_only) is WARNING. An expired input deadline makes the frame
// DANGEROUS at once (the deadline is its debounce).
//
// A DANGEROUS frame verdict opens a diagnosis: its cause, suspect and
// detail are latched, and every verdict after it is DANGEROUS with them
// until risk.evidence.clear_frames consecutive frames had no finding at all
// (no rule finding, the evidence quiet: every CUSUM below its warning level
// and the diagnosis's own hypothesis showing that its fault is gone, no
// expired deadline); the last of them closes it and is SAFE.
#include <cstdint>
#include <optional>
#include <string>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

class DecisionRule {
 public:
  explicit DecisionRule(const RiskSettings& risk);

  // The verdict on `frame` (its utime and seq) whose findings are final
  // (rules, estimate, plan and sequential evidence applied), judged in
  // frame order: every call counts one frame for the debounce and the
  // diagnosis, also while `expired_input` (the first expired deadline)
  // overrides the verdict. `evidence_quiet`: every CUSUM below its warning
  // level and the diagnosis's hypothesis cleared (SequentialEvidence::cleared);
  // `evidence_summary`: one line on them for an open diagnosis.
  risk_t decide(const discrepancy_t& frame, FrameFinding finding,
                const std::optional<FrameFinding>& expired_input, bool evidence_quiet = true,
                const std::string& evidence_summary = "");

  // Consecutive frames with a finding so far.
  int consecutive_findings() const { return consecutive_; }
  // A diagnosis is open (a DANGEROUS verdict not yet cleared).
  bool diagnosis_open() const { return open_.has_value(); }
  // The open diagnosis's finding as latched at the stop (nullptr: none open).
  const FrameFinding* open_finding() const { return open_ ? &open_->finding : nullptr; }
  // Consecutive clean frames since the last finding while a diagnosis is open.
  int clean_frames() const { return clean_frames_; }

 private:
  struct Diagnosis {
    FrameFinding finding;  // as latched; detail: the stop's verdict detail
    int64_t seq = 0;
  };
  int debounce_frames_;
  int sensor_debounce_frames_;
  int clear_frames_;
  int consecutive_ = 0;
  int clean_frames_ = 0;
  std::optional<Diagnosis> open_;
};

// The timeout verdict of an expired deadline: DANGEROUS, seq -1 (no frame),
// utime of the last judged frame.
risk_t timeout_verdict(int64_t last_frame_utime, const FrameFinding& expired_input);

}  // namespace tofguard::risk
