#include "tofguard/common/wire_checks.hpp"

#include <cmath>
#include <set>
#include <sstream>
#include <vector>

namespace tofguard {
namespace {

std::string expected(const std::string& field, const std::string& what, double got) {
  std::ostringstream s;
  s << field << ": expected " << what << ", got " << got;
  return s.str();
}

std::string check_size(int32_t width, int32_t height) {
  if (width <= 0 || width > kMaxImageSide) {
    return expected("width", "1.." + std::to_string(kMaxImageSide), width);
  }
  if (height <= 0 || height > kMaxImageSide) {
    return expected("height", "1.." + std::to_string(kMaxImageSide), height);
  }
  return "";
}

// "" when names are non-empty and unique.
std::string check_names(const std::vector<std::string>& names, const std::string& field) {
  std::set<std::string> seen;
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string at = field + "[" + std::to_string(i) + "]";
    if (names[i].empty()) return at + ": expected a joint name, got an empty string";
    if (!seen.insert(names[i]).second)
      return at + ": expected unique joint names, got '" + names[i] + "' twice";
  }
  return "";
}

// The rule is UnitQuaternion::check (camera_geometry.hpp).
std::string check_unit_quaternion(const double q[4], const std::string& field) {
  const auto v =
      UnitQuaternion::check(Eigen::Quaterniond(q[0], q[1], q[2], q[3]), kWireQuaternionTolerance, field);
  return v ? v->line() : "";
}

}  // namespace

std::string check_depth_image(const depth_image_t& image) {
  if (image.camera_id.empty()) return "camera_id: expected a camera name, got an empty string";
  if (image.utime <= 0) return expected("utime", "a capture time > 0", static_cast<double>(image.utime));
  if (image.seq < 0) return expected("seq", "a frame number >= 0", static_cast<double>(image.seq));
  if (auto problem = check_size(image.width, image.height); !problem.empty()) return problem;
  const int64_t pixels = int64_t{image.width} * image.height;
  if (image.num_pixels != pixels) {
    return expected("num_pixels", "width*height = " + std::to_string(pixels), image.num_pixels);
  }
  if (image.num_amplitude != 0 && image.num_amplitude != pixels) {
    return expected("num_amplitude", "0 or width*height = " + std::to_string(pixels), image.num_amplitude);
  }
  if (auto v = Intrinsics::check(image.width, image.height, image.fx, image.fy, image.cx, image.cy))
    return v->line();
  return "";
}

std::string check_depth_image_from(const depth_image_t& image, const std::string& camera_id) {
  std::string problem = check_depth_image(image);
  if (problem.empty() && image.camera_id != camera_id) {
    problem = "camera_id: expected '" + camera_id + "', got '" + image.camera_id + "'";
  }
  return problem;
}

std::string check_joint_state(const joint_state_t& state) {
  if (state.num_joints < 0) return expected("num_joints", "a count >= 0", state.num_joints);
  if (auto problem = check_names(state.name, "name"); !problem.empty()) return problem;
  for (int i = 0; i < state.num_joints; ++i) {
    const std::string at = "[" + std::to_string(i) + "]";
    if (!std::isfinite(state.position[i])) {
      return expected("position" + at + " (" + state.name[i] + ")", "a finite number", state.position[i]);
    }
    if (!std::isfinite(state.velocity[i])) {
      return expected("velocity" + at + " (" + state.name[i] + ")", "a finite number", state.velocity[i]);
    }
  }
  return "";
}

std::string check_camera_pose(const camera_pose_t& pose) {
  const auto v = CameraPose::check(
      pose.frame_id, Eigen::Vector3d(pose.translation[0], pose.translation[1], pose.translation[2]),
      Eigen::Quaterniond(pose.rotation[0], pose.rotation[1], pose.rotation[2], pose.rotation[3]),
      kWireQuaternionTolerance);
  return v ? v->line() : "";
}

std::string check_link_labels(const link_labels_t& labels) {
  if (labels.utime <= 0) return expected("utime", "a capture time > 0", static_cast<double>(labels.utime));
  if (labels.num_robot_links < 0 || labels.num_robot_links > labels.num_links) {
    return expected("num_robot_links", "0..num_links", labels.num_robot_links);
  }
  if (!labels.usable) {
    if (labels.unusable_reason.empty()) {
      return "unusable_reason: expected a reason for an unusable frame, got an empty string";
    }
    return "";
  }
  if (auto problem = check_size(labels.width, labels.height); !problem.empty()) return problem;
  const int64_t pixels = int64_t{labels.width} * labels.height;
  if (labels.num_pixels != pixels) {
    return expected("num_pixels", "width*height = " + std::to_string(pixels), labels.num_pixels);
  }
  return "";
}

std::string check_risk(const risk_t& risk) {
  if (risk.level < risk_t::SAFE || risk.level > risk_t::DANGEROUS) {
    return expected("level", "SAFE (0), WARNING (1) or DANGEROUS (2)", risk.level);
  }
  if (risk.cause < risk_t::CAUSE_NONE || risk.cause > risk_t::CAUSE_UNCLASSIFIED) {
    return expected("cause", "one of risk_t's CAUSE_ constants (0..6)", risk.cause);
  }
  if (!std::isfinite(risk.score)) return expected("score", "a finite number", risk.score);
  if (!std::isfinite(risk.threshold)) return expected("threshold", "a finite number", risk.threshold);
  return "";
}

std::string check_safety_status(const safety_status_t& status) {
  if (status.stop < safety_status_t::STOP_NONE || status.stop > safety_status_t::STOP_POWER_CUT) {
    return expected("stop", "one of safety_status_t's STOP_ constants (0..2)", status.stop);
  }
  if (status.cause < risk_t::CAUSE_NONE || status.cause > risk_t::CAUSE_UNCLASSIFIED) {
    return expected("cause", "one of risk_t's CAUSE_ constants (0..6)", status.cause);
  }
  if (status.motion_allowed && status.stop != safety_status_t::STOP_NONE) {
    return expected("stop", "STOP_NONE while motion_allowed is true", status.stop);
  }
  return "";
}

std::string check_motion_estimate(const motion_estimate_t& e) {
  if (e.utime <= 0) return expected("utime", "a capture time > 0", static_cast<double>(e.utime));
  if (e.seq < 0) return expected("seq", "a frame number >= 0", static_cast<double>(e.seq));
  if (e.camera_id.empty()) return "camera_id: expected a camera name, got an empty string";
  if (e.trigger < motion_estimate_t::TRIGGER_PERIODIC || e.trigger > motion_estimate_t::TRIGGER_REQUEST) {
    return expected("trigger", "one of the TRIGGER_ constants (0..2)", e.trigger);
  }
  if (!e.usable) {
    if (e.unusable_reason.empty())
      return "unusable_reason: expected a reason for an unusable estimate, got an empty string";
    return "";
  }
  if (e.num_frames < 1) return expected("num_frames", "a count of frames >= 1", e.num_frames);
  if (e.num_joints < 0) return expected("num_joints", "a count >= 0", e.num_joints);
  if (auto problem = check_names(e.joint_name, "joint_name"); !problem.empty()) return problem;
  for (int i = 0; i < e.num_joints; ++i) {
    const std::string at = "[" + std::to_string(i) + "] (" + e.joint_name[i] + ")";
    if (!std::isfinite(e.reported_position[i])) {
      return expected("reported_position" + at, "a finite number", e.reported_position[i]);
    }
    if (!std::isfinite(e.estimated_position[i])) {
      return expected("estimated_position" + at, "a finite number", e.estimated_position[i]);
    }
    if (!std::isfinite(e.position_sigma[i]) || e.position_sigma[i] < 0) {
      return expected("position_sigma" + at, "a finite sigma >= 0", e.position_sigma[i]);
    }
  }
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(e.correction_translation[i])) {
      return expected("correction_translation[" + std::to_string(i) + "]", "a finite number of metres",
                      e.correction_translation[i]);
    }
    if (!std::isfinite(e.estimated_translation[i])) {
      return expected("estimated_translation[" + std::to_string(i) + "]", "a finite number of metres",
                      e.estimated_translation[i]);
    }
  }
  if (auto problem = check_unit_quaternion(e.correction_rotation, "correction_rotation"); !problem.empty()) {
    return problem;
  }
  if (auto problem = check_unit_quaternion(e.estimated_rotation, "estimated_rotation"); !problem.empty()) {
    return problem;
  }
  if (!std::isfinite(e.correction_translation_sigma_m) || e.correction_translation_sigma_m < 0) {
    return expected("correction_translation_sigma_m", "a finite sigma >= 0",
                    e.correction_translation_sigma_m);
  }
  if (!std::isfinite(e.correction_rotation_sigma_rad) || e.correction_rotation_sigma_rad < 0) {
    return expected("correction_rotation_sigma_rad", "a finite sigma >= 0", e.correction_rotation_sigma_rad);
  }
  if (e.frame_id.empty()) return "frame_id: expected a URDF link name, got an empty string";
  if (e.num_points < 0 || e.num_inliers < 0 || e.num_inliers > e.num_points) {
    return expected("num_inliers", "0..num_points = " + std::to_string(e.num_points), e.num_inliers);
  }
  if (!std::isfinite(e.residual_before_mm) || e.residual_before_mm < 0) {
    return expected("residual_before_mm", "a finite residual >= 0", e.residual_before_mm);
  }
  if (!std::isfinite(e.residual_after_mm) || e.residual_after_mm < 0) {
    return expected("residual_after_mm", "a finite residual >= 0", e.residual_after_mm);
  }
  return "";
}

std::string check_planned_trajectory(const planned_trajectory_t& plan) {
  if (plan.num_joints <= 0) return expected("num_joints", "a count >= 1", plan.num_joints);
  if (plan.num_points <= 0) return expected("num_points", "a count >= 1", plan.num_points);
  if (auto problem = check_names(plan.joint_name, "joint_name"); !problem.empty()) return problem;
  for (int i = 0; i < plan.num_points; ++i) {
    const std::string at = "[" + std::to_string(i) + "]";
    if (plan.point_utime[i] <= 0) {
      return expected("point_utime" + at, "a time > 0", static_cast<double>(plan.point_utime[i]));
    }
    if (i > 0 && plan.point_utime[i] <= plan.point_utime[i - 1]) {
      return expected(
          "point_utime" + at,
          "strictly increasing times, previous " + std::to_string(plan.point_utime[i - 1]) + ", got",
          static_cast<double>(plan.point_utime[i]));
    }
    for (int j = 0; j < plan.num_joints; ++j) {
      if (!std::isfinite(plan.position[i][j])) {
        return expected("position" + at + "[" + std::to_string(j) + "] (" + plan.joint_name[j] + ")",
                        "a finite number", plan.position[i][j]);
      }
    }
  }
  return "";
}

std::string check_discrepancy(const discrepancy_t& d) {
  if (d.utime <= 0) return expected("utime", "a capture time > 0", static_cast<double>(d.utime));
  if (d.seq < 0) return expected("seq", "a frame number >= 0", static_cast<double>(d.seq));
  if (d.num_robot_links < 0 || d.num_robot_links > d.num_links) {
    return expected("num_robot_links", "0..num_links = " + std::to_string(d.num_links), d.num_robot_links);
  }
  if (!(d.invalid_fraction >= 0 && d.invalid_fraction <= 1)) {
    return expected("invalid_fraction", "a fraction in [0, 1]", d.invalid_fraction);
  }
  if (!(d.mismatch_fraction >= 0 && d.mismatch_fraction <= 1)) {
    return expected("mismatch_fraction", "a fraction in [0, 1]", d.mismatch_fraction);
  }
  if (!std::isfinite(d.p95_abs_dis_mm) || d.p95_abs_dis_mm < 0) {
    return expected("p95_abs_dis_mm", "a finite value >= 0 mm", d.p95_abs_dis_mm);
  }
  for (int i = 0; i < d.num_links; ++i) {
    if (d.link_compared[i] < 0 || d.link_match[i] < 0 || d.link_farther[i] < 0 ||
        d.link_match[i] > d.link_compared[i] || d.link_farther[i] > d.link_compared[i]) {
      return "link_compared[" + std::to_string(i) + "]: expected counts with 0 <= match, farther <= compared";
    }
  }
  if (!std::isfinite(d.near_arm_area_m2) || !std::isfinite(d.largest_blob_area_m2)) {
    return "near_arm_area_m2 / largest_blob_area_m2: expected finite areas";
  }
  return "";
}

std::string check_heartbeat(const heartbeat_t& hb) {
  if (hb.process.empty()) return "process: expected a process name, got an empty string";
  return "";
}

std::string check_sim_camera_fault(const sim_camera_fault_t& f) {
  auto finite3 = [](const double v[3]) {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
  };
  if (f.kind < sim_camera_fault_t::CLEAR || f.kind > sim_camera_fault_t::INTRUDING_OBJECT) {
    return "kind: expected 0..4, got " + std::to_string(f.kind);
  }
  if (f.kind != sim_camera_fault_t::CLEAR && !(f.duration_s > 0 && f.duration_s < 1e6)) {
    return "duration_s: expected a duration in (0, 1e6) s, got " + std::to_string(f.duration_s);
  }
  if (!finite3(f.drift_translation_m_per_s) || !finite3(f.drift_rotation_rad_per_s) ||
      !finite3(f.object_size_m) || !finite3(f.object_position_m) || !finite3(f.object_velocity_m_per_s)) {
    return "vectors: expected finite numbers";
  }
  if (f.kind == sim_camera_fault_t::INTRUDING_OBJECT &&
      !(f.object_size_m[0] > 0 && f.object_size_m[1] > 0 && f.object_size_m[2] > 0)) {
    return "object_size_m: expected 3 sizes > 0";
  }
  return "";
}

std::string check_sim_joint_fault(const sim_joint_fault_t& f) {
  if (f.joint.empty()) return "joint: expected a joint name, got an empty string";
  if (!std::isfinite(f.offset))
    return expected("offset", "a finite offset (rad, or m for a prismatic joint)", f.offset);
  return "";
}

}  // namespace tofguard
