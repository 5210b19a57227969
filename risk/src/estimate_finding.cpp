#include "tofguard/risk/estimate_finding.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "tofguard/risk_t.hpp"

namespace tofguard::risk {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// A joint offset in display units: degrees for revolute joints, mm for
// prismatic ones.
struct Offset {
  std::string joint;
  bool prismatic = false;
  double offset = 0;     // estimated - reported, rad or m
  double sigma = 0;      // rad or m
  double threshold = 0;  // rad or m
  double ratio = 0;      // |offset| / threshold
};

std::string in_units(double value, bool prismatic, int decimals) {
  return prismatic ? fixed(value * 1000.0, decimals) + " mm" : fixed(value * kRadToDeg, decimals) + "°";
}

}  // namespace

double correction_angle_rad(const motion_estimate_t& e) {
  const double norm = std::sqrt(e.correction_rotation[0] * e.correction_rotation[0] +
                                e.correction_rotation[1] * e.correction_rotation[1] +
                                e.correction_rotation[2] * e.correction_rotation[2] +
                                e.correction_rotation[3] * e.correction_rotation[3]);
  if (!(norm > 0)) return 0;
  return 2.0 * std::acos(std::min(1.0, std::abs(e.correction_rotation[0]) / norm));
}

FrameFinding classify_estimate(const motion_estimate_t& e, const RiskSettings& config,
                               const EstimateContext& context) {
  if (!e.usable || !e.converged) return {};

  // The most significant joint, normalised by its threshold.
  std::optional<Offset> joint;
  for (int i = 0; i < e.num_joints; ++i) {
    if (!e.observable[i]) continue;  // the image cannot see it: never named
    Offset o;
    o.joint = e.joint_name[i];
    o.prismatic = context.prismatic_joints.count(o.joint) > 0;
    o.offset = e.estimated_position[i] - e.reported_position[i];
    o.sigma = e.position_sigma[i];
    const double minimum =
        o.prismatic ? config.estimate_min_joint_offset_m : config.estimate_min_joint_offset_deg / kRadToDeg;
    o.threshold = std::max(config.estimate_sigmas * o.sigma, minimum);
    if (!(std::abs(o.offset) > o.threshold)) continue;
    o.ratio = o.threshold > 0 ? std::abs(o.offset) / o.threshold : HUGE_VAL;
    if (!joint || o.ratio > joint->ratio) joint = o;
  }

  // The camera correction.
  const double translation_m = std::sqrt(e.correction_translation[0] * e.correction_translation[0] +
                                         e.correction_translation[1] * e.correction_translation[1] +
                                         e.correction_translation[2] * e.correction_translation[2]);
  const double angle_rad = correction_angle_rad(e);
  const double translation_threshold =
      std::max(config.estimate_sigmas * e.correction_translation_sigma_m, config.estimate_min_translation_m);
  const double rotation_threshold = std::max(config.estimate_sigmas * e.correction_rotation_sigma_rad,
                                             config.estimate_min_rotation_deg / kRadToDeg);
  const bool translation_significant = translation_m > translation_threshold;
  const bool rotation_significant = angle_rad > rotation_threshold;
  double camera_ratio = 0;
  if (translation_significant) {
    camera_ratio = translation_threshold > 0 ? translation_m / translation_threshold : HUGE_VAL;
  }
  if (rotation_significant) {
    camera_ratio = std::max(camera_ratio, rotation_threshold > 0 ? angle_rad / rotation_threshold : HUGE_VAL);
  }
  const std::string residual = "; residual " + fixed(e.residual_before_mm, 1) + " mm before, " +
                               fixed(e.residual_after_mm, 1) + " mm after the estimate";

  if ((translation_significant || rotation_significant) && (!joint || camera_ratio >= joint->ratio)) {
    FrameFinding f;
    f.cause = risk_t::CAUSE_CALIBRATION_ERROR;
    if (translation_significant) {
      f.score = translation_m * 100.0;
      f.threshold = translation_threshold * 100.0;
    } else {
      f.score = angle_rad * kRadToDeg;
      f.threshold = rotation_threshold * kRadToDeg;
    }
    f.detail = "camera pose off by " + fixed(translation_m * 100.0, 1) + " cm and " +
               fixed(angle_rad * kRadToDeg, 1) + "° (seen vs configured; estimate, " +
               (translation_significant ? "cm" : "deg") + ")" + residual;
    if (joint)
      f.detail += "; joint " + joint->joint + " also off by " + in_units(joint->offset, joint->prismatic, 1);
    return f;
  }
  if (joint) {
    FrameFinding f;
    f.cause = risk_t::CAUSE_JOINT_ERROR;
    f.suspect = joint->joint;
    const double scale = joint->prismatic ? 1000.0 : kRadToDeg;
    f.score = std::abs(joint->offset) * scale;
    f.threshold = joint->threshold * scale;
    f.detail = "joint " + joint->joint + " reads " + in_units(std::abs(joint->offset), joint->prismatic, 1) +
               (joint->offset > 0 ? " less" : " more") + " than seen (estimate, " +
               (joint->prismatic ? "mm" : "deg") + "): offset " +
               in_units(joint->offset, joint->prismatic, 1) + " ± " +
               in_units(joint->sigma, joint->prismatic, 1) + residual;
    return f;
  }
  const bool unexplained = e.residual_after_mm > config.estimate_unexplained_residual_mm;
  if (unexplained || context.near_arm_evidence) {
    FrameFinding f;
    f.cause = risk_t::CAUSE_UNKNOWN_OBJECT;
    f.score = e.residual_after_mm;
    f.threshold = config.estimate_unexplained_residual_mm;
    f.detail = "unknown object (estimate residual mm): no joint or camera error explains the image, " +
               fixed(e.residual_after_mm, 1) + " mm residual left (limit " +
               fixed(config.estimate_unexplained_residual_mm, 1) + " mm)" +
               (context.near_arm_evidence ? ", surfaces near the arm" : "") + "; " +
               std::to_string(e.num_points - e.num_inliers) + " of " + std::to_string(e.num_points) +
               " model points are outliers";
    return f;
  }
  return {};
}

}  // namespace tofguard::risk
