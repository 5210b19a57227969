#pragma once
// The risk of one camera frame from its discrepancy summary: sensor faults
// first (unusable frame, invalid pixels, uncalibrated, frozen while the arm
// moves), then what the mismatch looks like: CALIBRATION_ERROR, JOINT_ERROR,
// UNKNOWN_OBJECT or UNCLASSIFIED. docs/safety-chain.md gives the rules.
// Pure logic; the debouncing into WARNING / DANGEROUS is DecisionRule's
// (decision_rule.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include "tofguard/common/risk_names.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/risk/protective_field.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

// What is wrong with a frame (cause CAUSE_NONE: nothing).
struct FrameFinding {
  int8_t cause = 0;  // risk_t::CAUSE_*
  // The joint for a joint error; the channel or component for a fault.
  std::string suspect;
  // The deciding score and its threshold; their unit is named in detail.
  double score = 0;
  double threshold = 0;
  std::string detail;
  // DANGEROUS at once, no frame debounce: a sequential test that crossed
  // its threshold (the CUSUM is its debounce).
  bool at_once = false;
  // WARNING, never DANGEROUS by itself: a sequential test's evidence is
  // growing but has not crossed.
  bool warning_only = false;
  // The sequential test that crossed when it is not the one the cause
  // names ("camera" or a joint; empty: the cause's own): its clearing test
  // closes the diagnosis.
  std::string crossed_test = {};
};

struct ClassifierContext {
  // The configured channel names and rules.
  std::string depth_channel = "TOF_DEPTH";
  std::string labels_channel = "TOF_LABELS";
  // True when the joint state at the frame's capture time (the newest
  // taken at or before its utime) has a joint faster than
  // risk.sensor.moving_joint_speed_rad_s.
  bool arm_moving = false;
  // The protective and warning fields at the frame (protective_field.hpp):
  // S and S + margin for the arm's speed bound at its capture; +infinity
  // when that speed cannot be bounded (why in field_unbounded_reason).
  FieldSize field;
  std::string field_unbounded_reason;
};

// A robot link seen well enough to judge (>= risk.joint_error.min_link_pixels
// compared pixels, silhouettes left out).
struct LinkView {
  std::string name;
  int compared = 0;
  double mismatch = 0;  // (compared - match) / compared
  double missing = 0;   // farther / compared
};

// What the frame rules look at: the frame, the robot's tree, the thresholds
// and the context, with the per-link views every mismatch rule shares.
class FrameEvidence {
 public:
  FrameEvidence(const discrepancy_t& frame, const robot_model::KinematicTree& robot,
                const RiskSettings& config, const ClassifierContext& context)
      : frame(frame), robot(robot), config(config), context(context) {}

  const discrepancy_t& frame;
  const robot_model::KinematicTree& robot;
  const RiskSettings& config;
  const ClassifierContext& context;

  // The visible robot links, in discrepancy_t order.
  const std::vector<LinkView>& visible_links() const;
  // Compared and matching pixels over all environment links.
  int64_t environment_compared() const;
  int64_t environment_match() const;

 private:
  // Built on first use: the sensor rules judge frames (unusable ones
  // among them) without per-link counts.
  void build_link_views() const;
  mutable bool built_ = false;
  mutable std::vector<LinkView> visible_;
  mutable int64_t environment_compared_ = 0;
  mutable int64_t environment_match_ = 0;
};

// One frame rule: its finding, or a finding with cause CAUSE_NONE when it
// does not apply.
struct FrameRule {
  const char* name;
  FrameFinding (*apply)(const FrameEvidence& evidence);
};

// The frame rules in order of precedence (docs/safety-chain.md, "Frame
// rules"); the first that applies is the frame's finding. A new rule is a
// new entry at its place in this list.
const std::vector<FrameRule>& frame_rules();

// The first finding of frame_rules(), or none.
FrameFinding classify_frame(const discrepancy_t& frame, const robot_model::KinematicTree& robot,
                            const RiskSettings& config, const ClassifierContext& context);

// `value` with `decimals` digits after the point, for detail lines.
std::string fixed(double value, int decimals);

// is_fault_cause and is_model_mismatch (which causes are faults, which are
// model mismatches) are the wire's, in common/risk_names.hpp: the estimator
// triggers on the same model-mismatch causes.

}  // namespace tofguard::risk
