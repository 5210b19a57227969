#pragma once
// What the motion estimate (motion_estimate_t on MOTION_ESTIMATE) says is
// wrong with a frame: a joint that reads other than the image shows, a
// camera pose off from the configured one, or neither although the model
// still does not fit (an unknown object). Pure logic; docs/safety-chain.md
// ("Using the motion estimate") gives the rules and how tofguard-risk
// combines the result with the discrepancy rules (it never makes a frame
// safer).
#include <set>
#include <string>

#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

struct EstimateContext {
  // Joints whose positions are metres (prismatic); all others radians.
  std::set<std::string> prismatic_joints;
  // The frame's discrepancy shows nearer surfaces near the arm (its
  // near_arm_area_m2 >= risk.unknown_object_min_area_m2).
  bool near_arm_evidence = false;
};

// For a usable, converged estimate (anything else: no finding):
//  - a joint is significant when it is observable and
//    |estimated - reported| > max(estimate.sigmas * sigma, minimum offset);
//  - the camera correction is significant when its translation or its
//    rotation angle exceeds max(estimate.sigmas * its sigma, its minimum);
//  - the significant joint with the largest |offset| / threshold, or the
//    camera if its ratio is larger, is the finding: JOINT_ERROR (suspect the
//    joint, score |offset| in degrees or mm) or CALIBRATION_ERROR (score the
//    translation in cm or the rotation in degrees);
//  - neither, yet residual_after_mm > estimate.unexplained_residual_mm or
//    near-arm evidence: UNKNOWN_OBJECT (score residual_after_mm);
//  - else no finding (the estimate explains nothing).
FrameFinding classify_estimate(const motion_estimate_t& estimate, const RiskSettings& config,
                               const EstimateContext& context = {});

// The camera correction's rotation angle, radians (0..pi).
double correction_angle_rad(const motion_estimate_t& estimate);

}  // namespace tofguard::risk
