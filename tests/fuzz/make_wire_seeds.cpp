// Writes the seed corpus of wire_messages_fuzz and spy_format_fuzz: one
// small, valid encoded message of each type a process receives, each
// passing its wire check (wire_checks.hpp), so that the fuzzer starts
// from messages that reach past decoding and checking. Made at build time
// (scripts/fuzz runs it) because the first 8 bytes are the type's
// fingerprint, which changes with its .lcm file.
//
// Usage: make_wire_seeds OUTPUT_FOLDER
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "fuzz_auth_key.hpp"
#include "tofguard/authenticated_message_t.hpp"
#include "tofguard/camera_pose_t.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_image_t.hpp"
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

namespace {

using namespace tofguard;

std::string folder;
int failures = 0;

template <class T>
void write(const std::string& name, const T& message) {
  std::vector<char> bytes(static_cast<size_t>(message.getEncodedSize()));
  const int size = message.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  std::ofstream out(folder + "/" + name, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), size);
  if (size < 0 || !out) {
    std::cerr << "make_wire_seeds: cannot write " << folder << "/" << name << "\n";
    ++failures;
  }
}

const std::vector<std::string> kJoints = {"a1", "a2", "a3"};

void depth_images() {
  depth_image_t m{};
  m.utime = 1000;
  m.seq = 1;
  m.camera_id = "tof-mast";
  m.width = 4;
  m.height = 3;
  m.fx = m.fy = 5;
  m.cx = 1.5;
  m.cy = 1;
  m.calibrated = true;
  m.num_pixels = 12;
  m.depth_mm = {0, 500, 1000, 1500, 2000, 2500, 3000, 3500, 4000, 4500, 5000, -1};
  write("depth_image", m);
  m.num_amplitude = 12;
  m.amplitude.assign(12, 100);
  write("depth_image_amplitude", m);
}

void joint_states() {
  joint_state_t m{};
  m.utime = 1000;
  m.robot_id = "friend-sim";
  m.num_joints = 3;
  m.name = kJoints;
  m.position = {0.1, -0.2, 0.3};
  m.velocity = {0, 0.01, -0.01};
  write("joint_state", m);
}

void camera_poses() {
  camera_pose_t m{};
  m.utime = 1000;
  m.camera_id = "tof-mast";
  m.frame_id = "world";
  m.translation[2] = 1.8;
  m.rotation[0] = 1;
  write("camera_pose", m);
}

void link_labels() {
  link_labels_t m{};
  m.utime = 1000;
  m.seq = 1;
  m.camera_id = "tof-mast";
  m.usable = true;
  m.width = 3;
  m.height = 2;
  m.num_robot_links = 2;
  m.num_links = 3;
  m.link_name = {"link1", "link2", "table"};
  m.num_pixels = 6;
  m.label = {0, 1, 2, 1000, 1001, 2000};
  m.num_joints = 2;
  m.joint_name = {"a1", "a2"};
  m.num_axes = 2;
  m.axis_joint = {0, 1};
  m.axis_multiplier = {1, -1};
  m.axis_prismatic = {false, true};
  m.axis_origin_m = {{0, 0, 0.1}, {0, 0, 0.3}};
  m.axis_direction = {{0, 0, 1}, {1, 0, 0}};
  m.axis_parent = {-1, 0};
  m.num_link_axes = 2;
  m.link_axis = {0, 1};
  write("link_labels", m);
  link_labels_t unusable{};
  unusable.utime = 1000;
  unusable.camera_id = "tof-mast";
  unusable.unusable_reason = "no rendering";
  write("link_labels_unusable", unusable);
}

void discrepancies() {
  discrepancy_t m{};
  m.utime = 1000;
  m.seq = 1;
  m.camera_id = "tof-mast";
  m.usable = true;
  m.width = 4;
  m.height = 3;
  m.num_pixels = 12;
  m.num_compared = 10;
  m.invalid_fraction = 0.1f;
  m.mismatch_fraction = 0.2f;
  m.p95_abs_dis_mm = 12;
  m.num_robot_links = 1;
  m.num_links = 2;
  m.link_name = {"link1", "table"};
  m.link_compared = {5, 5};
  m.link_match = {4, 5};
  m.link_farther = {1, 0};
  m.link_nearer = {0, 0};
  m.link_invalid = {0, 1};
  m.link_median_dis_mm = {3, 1};
  m.evidence_available = true;
  m.num_link_bias = 2;
  m.link_bias_mm = {1, -1};
  m.link_bias_sigma_mm = {0.5f, 0.5f};
  m.camera_fit_pixels = 10;
  for (int k = 0; k < 6; ++k) m.camera_information[7 * k] = 1;
  for (int r = 0; r < 4; ++r) {
    m.camera_region_fit_pixels[r] = 2;
    for (int a = 0; a < 6; ++a) m.camera_region_information[6 * r + a] = 0.25;
  }
  m.num_joints = 3;
  m.joint_name = kJoints;
  m.joint_fit_pixels = {3, 3, 4};
  m.joint_score = {0.1, -0.1, 0};
  m.joint_information = {1, 2, 3};
  m.joint_naming_score = {0, 0, 0};
  m.joint_naming_information = {1, 1, 1};
  m.joint_static_bound = {0, 0.5, 0};
  m.joint_search_offset = {0, 0.01, 0};
  m.joint_search_gain = {0, 1, 0};
  m.camera_search_axis = -1;
  m.joint_reach_m = {0.9, 0.6, 0.2};
  m.robot_fit_pixels = 5;
  m.search_points = 3;
  write("discrepancy", m);
}

// `message` signed for `channel` with the fuzz key, as
// authenticated_message_t (the signer's work, done here with the
// header-only tag so that the fuzz tree needs no tofguard_auth library).
template <class T>
void write_signed(const std::string& name, const std::string& channel, const T& message) {
  authenticated_message_t m{};
  m.utime = 1000;
  m.seq = 1000;
  m.channel = channel;
  const auth::AuthKey key = fuzz_auth_key();
  m.key_id = key.id;
  m.payload.resize(static_cast<size_t>(message.getEncodedSize()));
  message.encode(m.payload.data(), 0, static_cast<int>(m.payload.size()));
  m.payload_size = static_cast<int32_t>(m.payload.size());
  const auth::Tag tag = auth::compute_tag(key, m);
  std::copy(tag.begin(), tag.end(), m.tag);
  write(name, m);
}

void risks_and_status() {
  risk_t r{};
  r.utime = 1000;
  r.seq = 1;
  r.level = risk_t::DANGEROUS;
  r.cause = risk_t::CAUSE_JOINT_ERROR;
  r.suspect = "a2";
  r.score = 25;
  r.threshold = 20.6;
  r.detail = "joint a2 3 deg off";
  write("risk", r);
  safety_status_t s{};
  s.utime = 1000;
  s.seq = 1;
  s.stop = safety_status_t::STOP_SOFTWARE;
  s.latched = true;
  s.cause = risk_t::CAUSE_JOINT_ERROR;
  s.reason = "risk DANGEROUS";
  s.since_utime = 900;
  write("safety_status", s);
  write_signed("risk_signed", "SAFETY_RISK", r);
  write_signed("safety_status_signed", "SAFETY_STATUS", s);
  heartbeat_t h{};
  h.utime = 1000;
  h.process = "tofguard-camera";
  h.pid = 42;
  h.seq = 1;
  h.status = "ok";
  write("heartbeat", h);
}

void estimates() {
  motion_estimate_t m{};
  m.utime = 1000;
  m.seq = 1;
  m.camera_id = "tof-mast";
  m.trigger = motion_estimate_t::TRIGGER_WARNING;
  m.usable = true;
  m.converged = true;
  m.iterations = 4;
  m.num_frames = 3;
  m.num_joints = 3;
  m.joint_name = kJoints;
  m.reported_position = {0.1, 0.2, 0.3};
  m.estimated_position = {0.1, 0.25, 0.3};
  m.position_sigma = {0.01, 0.01, 0.01};
  m.observable = {true, true, false};
  m.correction_rotation[0] = 1;
  m.frame_id = "world";
  m.estimated_translation[2] = 1.8;
  m.estimated_rotation[0] = 1;
  m.num_points = 100;
  m.num_inliers = 90;
  m.residual_before_mm = 20;
  m.residual_after_mm = 5;
  write("motion_estimate", m);
  motion_estimate_t unusable{};
  unusable.utime = 1000;
  unusable.camera_id = "tof-mast";
  unusable.unusable_reason = "too few points";
  write("motion_estimate_unusable", unusable);
}

void plans() {
  planned_trajectory_t m{};
  m.utime = 1000;
  m.num_joints = 3;
  m.joint_name = kJoints;
  m.num_points = 2;
  m.point_utime = {1000, 21000};
  m.position = {{0, 0, 0}, {0.01, 0.02, 0.03}};
  write("planned_trajectory", m);
}

void tools_and_faults() {
  reset_request_t q{};
  q.utime = 1000;
  q.request_id = 7;
  q.who = "operator";
  q.why = "checked the arm";
  write("reset_request", q);
  write_signed("reset_request_signed", "SAFETY_RESET", q);
  reset_reply_t a{};
  a.utime = 1001;
  a.request_id = 7;
  a.accepted = true;
  a.reason = "ok";
  write("reset_reply", a);
  power_relay_t p{};
  p.utime = 1000;
  p.seq = 1;
  p.power_enabled = true;
  p.reason = "motion allowed";
  write("power_relay", p);
  sim_camera_fault_t c{};
  c.utime = 1000;
  c.camera_id = "tof-mast";
  c.kind = sim_camera_fault_t::INTRUDING_OBJECT;
  c.duration_s = 2;
  c.object_size_m[0] = c.object_size_m[1] = c.object_size_m[2] = 0.1;
  c.object_position_m[0] = 0.5;
  write("sim_camera_fault", c);
  sim_joint_fault_t j{};
  j.utime = 1000;
  j.joint = "a4";
  j.offset = 0.1745;
  write("sim_joint_fault", j);
  sim_controller_fault_t f{};
  f.utime = 1000;
  f.ignore_speed_limit = true;
  f.drive_joint = "a1";
  f.drive_rad_s = 1.5;
  write("sim_controller_fault", f);
  discrepancy_image_t d{};
  d.utime = 1000;
  d.camera_id = "tof-mast";
  d.width = 2;
  d.height = 1;
  d.num_bytes = 6;
  d.rgb = {255, 0, 0, 0, 255, 0};
  write("discrepancy_image", d);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_wire_seeds OUTPUT_FOLDER\n";
    return 2;
  }
  folder = argv[1];
  depth_images();
  joint_states();
  camera_poses();
  link_labels();
  discrepancies();
  risks_and_status();
  estimates();
  plans();
  tools_and_faults();
  return failures == 0 ? 0 : 1;
}
