#pragma once
// One message of each wire type with every field set to a distinctive value,
// shared by the round-trip test (C++) and mirrored in DecodeLog.java.
#include <cstdint>
#include <vector>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/reset_reply_t.hpp"
#include "tofguard/reset_request_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"

namespace tofguard::test {

// A message's wire bytes (fingerprint first).
template <class T>
std::vector<uint8_t> encoded(const T& message) {
  std::vector<uint8_t> bytes(message.getEncodedSize());
  message.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

inline depth_image_t sample_depth_image() {
  depth_image_t m;
  m.utime = 1700000000123456;
  m.seq = 42;
  m.camera_id = "tof-test";
  m.width = 4;
  m.height = 3;
  m.fx = 221.5;
  m.fy = 220.25;
  m.cx = 1.75;
  m.cy = 1.25;
  m.calibrated = true;
  m.num_pixels = 12;
  m.num_amplitude = 12;
  for (int i = 0; i < 12; ++i) {
    m.depth_mm.push_back(static_cast<int16_t>(i == 5 ? -1 : 500 + 37 * i));
    m.amplitude.push_back(static_cast<int16_t>(100 * i));
  }
  return m;
}

inline joint_state_t sample_joint_state() {
  joint_state_t m;
  m.utime = 1700000000200000;
  m.robot_id = "friend-test";
  m.num_joints = 3;
  m.name = {"a1", "a2", "a3"};
  m.position = {0.5, -1.25, 3.0};
  m.velocity = {0.1, 0.0, -0.2};
  return m;
}

inline camera_pose_t sample_camera_pose() {
  camera_pose_t m;
  m.utime = 1700000000300000;
  m.camera_id = "tof-test";
  m.frame_id = "world";
  m.translation[0] = -0.35;
  m.translation[1] = -0.2;
  m.translation[2] = 1.55;
  m.rotation[0] = 0.5;
  m.rotation[1] = -0.5;
  m.rotation[2] = 0.5;
  m.rotation[3] = -0.5;
  return m;
}

inline risk_t sample_risk() {
  risk_t m;
  m.utime = 1700000000123456;
  m.seq = 42;
  m.level = risk_t::DANGEROUS;
  m.cause = risk_t::CAUSE_JOINT_ERROR;
  m.suspect = "a4";
  m.score = 123.5;
  m.threshold = 50.0;
  m.detail = "joint a4 reads 10.0 deg less than seen";
  return m;
}

inline safety_status_t sample_safety_status() {
  safety_status_t m;
  m.utime = 1700000000400000;
  m.seq = 7;
  m.motion_allowed = false;
  m.stop = safety_status_t::STOP_SOFTWARE;
  m.latched = true;
  m.cause = risk_t::CAUSE_JOINT_ERROR;
  m.reason = "DANGEROUS: joint error, suspect a4";
  m.since_utime = 1700000000123999;
  return m;
}

inline link_labels_t sample_link_labels() {
  link_labels_t m{};
  m.utime = 1700000000123456;
  m.seq = 42;
  m.camera_id = "tof-test";
  m.usable = true;
  m.unusable_reason = "";
  m.width = 3;
  m.height = 2;
  m.num_robot_links = 2;
  m.num_links = 3;
  m.link_name = {"link1", "link2", "table"};
  m.num_pixels = 6;
  m.label = {0, 1, 2, link_labels_t::ENVIRONMENT_FIRST, 0, 1};
  m.num_joints = 0;
  m.num_axes = 0;
  m.num_link_axes = 0;
  return m;
}

inline heartbeat_t sample_heartbeat() {
  heartbeat_t m;
  m.utime = 1700000000500000;
  m.process = "tofguard-renderer";
  m.pid = 4242;
  m.seq = 99;
  m.frames_in = 1000;
  m.frames_out = 998;
  m.frames_dropped = 2;
  m.decode_errors = 3;
  m.validation_errors = 4;
  m.last_frame_utime = 1700000000123456;
  m.status = "running";
  return m;
}

inline reset_request_t sample_reset_request() {
  reset_request_t m;
  m.utime = 1700000000600000;
  m.request_id = 123456789;
  m.who = "operator";
  m.why = "object removed";
  return m;
}

inline reset_reply_t sample_reset_reply() {
  reset_reply_t m;
  m.utime = 1700000000600100;
  m.request_id = 123456789;
  m.accepted = false;
  m.reason = "refused: current risk is DANGEROUS";
  return m;
}

}  // namespace tofguard::test
