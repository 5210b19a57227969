#include "tofguard/spy/message_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <iomanip>
#include <map>
#include <sstream>

#include "tofguard/authenticated_message_t.hpp"
#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/decode.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/power_relay_t.hpp"
#include "tofguard/reset_reply_t.hpp"
#include "tofguard/reset_request_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/sim_camera_fault_t.hpp"
#include "tofguard/sim_controller_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"
#include "tofguard/speed_limit_t.hpp"

namespace tofguard::spy {
namespace {

std::string yes_no(bool b) { return b ? "true" : "false"; }

std::string format(const depth_image_t& m) {
  int valid = 0;
  for (int16_t d : m.depth_mm) valid += d > 0;
  std::ostringstream s;
  s << "utime=" << m.utime << " seq=" << m.seq << " camera=" << m.camera_id << " " << m.width << "x"
    << m.height << " valid=" << std::fixed << std::setprecision(1)
    << (m.num_pixels > 0 ? 100.0 * valid / m.num_pixels : 0.0) << "% calibrated=" << yes_no(m.calibrated);
  return s.str();
}

std::string format(const joint_state_t& m) {
  std::ostringstream s;
  s << "utime=" << m.utime << " robot=" << m.robot_id << std::fixed << std::setprecision(4);
  for (int i = 0; i < m.num_joints; ++i) s << " " << m.name[i] << "=" << m.position[i];
  return s.str();
}

std::string format(const camera_pose_t& m) {
  std::ostringstream s;
  s << "utime=" << m.utime << " camera=" << m.camera_id << " frame=" << m.frame_id << std::fixed
    << std::setprecision(4) << " t=[" << m.translation[0] << "," << m.translation[1] << ","
    << m.translation[2] << "] q_wxyz=[" << m.rotation[0] << "," << m.rotation[1] << "," << m.rotation[2]
    << "," << m.rotation[3] << "]";
  return s.str();
}

std::string format(const risk_t& m) {
  std::ostringstream s;
  s << "utime=" << m.utime << " seq=" << m.seq << " " << risk_level_name(m.level) << " "
    << risk_cause_name(m.cause);
  if (!m.suspect.empty()) s << " suspect=" << m.suspect;
  s << " score=" << m.score << " threshold=" << m.threshold;
  if (!m.detail.empty()) s << " | " << m.detail;
  return s.str();
}

std::string format(const safety_status_t& m) {
  std::ostringstream s;
  s << "seq=" << m.seq << " motion_allowed=" << yes_no(m.motion_allowed) << " stop=" << stop_name(m.stop)
    << " latched=" << yes_no(m.latched) << " cause=" << risk_cause_name(m.cause) << " | " << m.reason;
  return s.str();
}

std::string format(const speed_limit_t& m) {
  std::ostringstream s;
  s << "utime=" << m.utime << " seq=" << m.seq << std::fixed << std::setprecision(2)
    << " max_arm_speed=" << m.max_arm_speed_m_s << " m/s set_by=" << speed_limit_setter_name(m.set_by);
  if (!m.body_region.empty()) s << " region=" << m.body_region;
  if (m.separation_m >= 0) s << " separation=" << m.separation_m << " m";
  s << " arm_speed=" << m.arm_speed_m_s << " m/s valid_for=" << m.valid_for_ms << " ms | " << m.reason;
  return s.str();
}

std::string format(const heartbeat_t& m) {
  std::ostringstream s;
  s << m.process << " pid=" << m.pid << " seq=" << m.seq << " in=" << m.frames_in << " out=" << m.frames_out
    << " dropped=" << m.frames_dropped << " decode_errors=" << m.decode_errors
    << " validation_errors=" << m.validation_errors << " | " << m.status;
  return s.str();
}

std::string format(const link_labels_t& m) {
  std::ostringstream s;
  s << "utime=" << m.utime << " seq=" << m.seq << " camera=" << m.camera_id << " usable=" << yes_no(m.usable);
  if (!m.usable) s << " (" << m.unusable_reason << ")";
  s << " " << m.width << "x" << m.height << " links=" << m.num_links;
  return s.str();
}

std::string format(const reset_request_t& m) {
  return "request_id=" + std::to_string(m.request_id) + " who=" + m.who + " | " + m.why;
}

std::string format(const reset_reply_t& m) {
  return "request_id=" + std::to_string(m.request_id) + " accepted=" + yes_no(m.accepted) + " | " + m.reason;
}

std::string format(const power_relay_t& m) {
  return "seq=" + std::to_string(m.seq) + " power_enabled=" + yes_no(m.power_enabled) + " | " + m.reason;
}

std::string format(const discrepancy_t& m) {
  std::ostringstream s;
  s << "utime=" << m.utime << " seq=" << m.seq << " usable=" << yes_no(m.usable);
  if (!m.usable) return s.str() + " (" + m.unusable_reason + ")";
  s << std::fixed << std::setprecision(1) << " match=" << m.num_match
    << " robot_missing=" << m.num_robot_missing << " occluded=" << m.num_occluded
    << " unexpected=" << m.num_unexpected_surface << " env_missing=" << m.num_environment_missing
    << " invalid=" << m.num_invalid << " median_abs_dis_mm=" << m.median_abs_dis_mm
    << " robot_median_mm=" << m.robot_median_dis_mm << " env_median_mm=" << m.environment_median_dis_mm
    << " blob_px=" << m.largest_blob_pixels << " near_arm_px=" << m.near_arm_pixels << " |";
  for (int i = 0; i < m.num_links; ++i) {
    if (m.link_compared[i] == 0) continue;
    s << " " << m.link_name[i] << "=" << m.link_match[i] << "/" << m.link_compared[i] << "(far "
      << m.link_farther[i] << ", near " << m.link_nearer[i] << ")";
  }
  // The user (docs/safety-chain.md, "The user"): the nearest region to the
  // arm, and what the camera saw of the user.
  if (m.num_body_regions > 0 &&
      m.body_region_separation_m.size() == static_cast<size_t>(m.num_body_regions)) {
    int nearest = 0;
    int64_t modelled = 0, missing = 0, seen = 0;
    for (int k = 0; k < m.num_body_regions; ++k) {
      if (m.body_region_separation_m[k] < m.body_region_separation_m[nearest]) nearest = k;
      if (static_cast<size_t>(k) < m.body_region_modelled_pixels.size()) {
        modelled += m.body_region_modelled_pixels[k];
        missing += m.body_region_missing_pixels[k];
        seen += m.body_region_seen_pixels[k];
      }
    }
    s << std::setprecision(2) << " | user: nearest " << m.body_region[nearest] << " "
      << m.body_region_separation_m[nearest] << " m (model), seen " << seen << " px, missing " << missing
      << " of " << modelled << " modelled px, hiding " << m.num_robot_hidden_by_user << " arm px";
  }
  return s.str();
}

std::string format(const sim_controller_fault_t& m) {
  std::ostringstream s;
  s << "ignore_speed_limit=" << (m.ignore_speed_limit ? "yes" : "no");
  if (!m.drive_joint.empty())
    s << " drive " << m.drive_joint << " at " << std::fixed << std::setprecision(2) << m.drive_rad_s
      << " rad/s";
  return s.str();
}

std::string format(const sim_joint_fault_t& m) {
  std::ostringstream s;
  s << "joint=" << m.joint << " offset=" << m.offset;
  return s.str();
}

// Joint offsets in degrees (estimated - reported), only the observable
// joints; the camera correction in mm and degrees.
std::string format(const motion_estimate_t& m) {
  std::ostringstream s;
  s << "utime=" << m.utime << " seq=" << m.seq << " trigger=" << static_cast<int>(m.trigger)
    << " usable=" << yes_no(m.usable);
  if (!m.usable) return s.str() + " (" + m.unusable_reason + ")";
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  s << " converged=" << yes_no(m.converged) << " iterations=" << m.iterations << " frames=" << m.num_frames
    << std::fixed << std::setprecision(1) << " residual_mm=" << m.residual_before_mm << "->"
    << m.residual_after_mm << " |";
  for (int i = 0; i < m.num_joints; ++i) {
    if (!m.observable[i]) continue;
    s << " " << m.joint_name[i] << "=" << std::showpos
      << (m.estimated_position[i] - m.reported_position[i]) * kDeg << std::noshowpos << "±"
      << m.position_sigma[i] * kDeg << "°";
  }
  const double w = std::min(1.0, std::abs(m.correction_rotation[0]));
  s << " | camera_mm=" << m.correction_translation[0] * 1000 << "," << m.correction_translation[1] * 1000
    << "," << m.correction_translation[2] * 1000 << " camera_deg=" << 2 * std::acos(w) * kDeg
    << " compute_ms=" << m.compute_us / 1000.0;
  return s.str();
}

std::string format(const planned_trajectory_t& m) {
  std::ostringstream s;
  s << "utime=" << m.utime << " joints=" << m.num_joints << " points=" << m.num_points;
  if (m.num_points > 0) {
    // In double: the message is not checked here, and the difference of two
    // arbitrary int64 times overflows (tests/fuzz/regressions/spy_format/).
    s << " span_ms=" << std::fixed << std::setprecision(1)
      << (static_cast<double>(m.point_utime.back()) - static_cast<double>(m.point_utime.front())) / 1000.0;
  }
  return s.str();
}

std::string format(const sim_camera_fault_t& m) {
  std::ostringstream s;
  s << "camera=" << m.camera_id << " kind=" << m.kind << " duration_s=" << m.duration_s;
  return s.str();
}

// A signed envelope (docs/security.md): what it claims to carry. The spy
// holds no key, so the tag is not checked here.
std::string format(const authenticated_message_t& m) {
  std::ostringstream s;
  const std::string inner = type_of(m.payload.data(), static_cast<int>(m.payload.size()));
  s << "for=" << m.channel << " seq=" << m.seq << " key=" << m.key_id
    << " payload=" << (inner.empty() ? "?" : inner) << " (" << m.payload.size() << " bytes, tag not checked)";
  return s.str();
}

using Formatter = std::function<std::optional<std::string>(const void*, int)>;

template <class T>
std::pair<int64_t, std::pair<std::string, Formatter>> entry() {
  Formatter f = [](const void* data, int size) -> std::optional<std::string> {
    const std::optional<T> m = decode_message<T>(data, size);
    if (!m) return std::nullopt;
    return format(*m);
  };
  return {T::getHash(), {T::getTypeName(), f}};
}

const std::map<int64_t, std::pair<std::string, Formatter>>& formatters() {
  static const std::map<int64_t, std::pair<std::string, Formatter>> table = {
      entry<depth_image_t>(),      entry<joint_state_t>(),
      entry<camera_pose_t>(),      entry<risk_t>(),
      entry<safety_status_t>(),    entry<heartbeat_t>(),
      entry<link_labels_t>(),      entry<reset_request_t>(),
      entry<reset_reply_t>(),      entry<power_relay_t>(),
      entry<sim_joint_fault_t>(),  entry<discrepancy_t>(),
      entry<motion_estimate_t>(),  entry<planned_trajectory_t>(),
      entry<sim_camera_fault_t>(), entry<authenticated_message_t>(),
      entry<speed_limit_t>(),      entry<sim_controller_fault_t>(),
  };
  return table;
}

int64_t fingerprint(const void* data, int size) {
  if (size < 8) return 0;
  const auto* b = static_cast<const uint8_t*>(data);
  uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | b[i];  // big-endian on the wire
  return static_cast<int64_t>(hash);
}

}  // namespace

std::string type_of(const void* data, int size) {
  const auto it = formatters().find(fingerprint(data, size));
  return it == formatters().end() ? "" : it->second.first;
}

std::string format_message(const std::string& channel, const void* data, int size) {
  const int64_t hash = fingerprint(data, size);
  const auto it = formatters().find(hash);
  if (it != formatters().end()) {
    if (auto text = it->second.second(data, size)) return channel + " " + it->second.first + " " + *text;
  }
  std::ostringstream s;
  s << channel << " ? fingerprint 0x" << std::hex << std::setw(16) << std::setfill('0')
    << static_cast<uint64_t>(hash) << std::dec << " (" << size << " bytes)";
  return s.str();
}

}  // namespace tofguard::spy
