#pragma once
// The risk of one camera frame from its discrepancy summary: sensor faults
// first (unusable frame, invalid pixels, uncalibrated, frozen while the arm
// moves), then what the mismatch looks like: CALIBRATION_ERROR, JOINT_ERROR,
// UNKNOWN_OBJECT or UNCLASSIFIED. docs/safety-chain.md gives the rules.
// Pure logic; the debouncing into WARNING / DANGEROUS is RiskMonitor's.
#include <cstdint>
#include <string>

#include "tofguard/risk/robot_tree.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/risk/risk_settings.hpp"
#include "tofguard/discrepancy_t.hpp"

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
};

struct ClassifierContext {
  // The configured channel names and rules.
  std::string depth_channel = "TOF_DEPTH";
  std::string labels_channel = "TOF_LABELS";
  // True when the joint state at the frame's capture time (the newest
  // taken at or before its utime) has a joint faster than
  // risk.sensor.moving_joint_speed_rad_s.
  bool arm_moving = false;
};

FrameFinding classify_frame(const discrepancy_t& frame, const RobotTree& robot, const RiskSettings& config,
                            const ClassifierContext& context);

// `value` with `decimals` digits after the point, for detail lines.
std::string fixed(double value, int decimals);

// is_fault_cause and is_model_mismatch (which causes are faults, which are
// model mismatches) are the wire's, in common/risk_names.hpp: the estimator
// triggers on the same model-mismatch causes.

}  // namespace tofguard::risk
