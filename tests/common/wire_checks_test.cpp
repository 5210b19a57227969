// The message checks that moved into common/src/wire_checks.cpp (one each):
// discrepancy_t (the union of tofguard-risk's and tofguard-estimator's
// former checks), heartbeat_t, sim_camera_fault_t, sim_joint_fault_t.
#include "tofguard/common/wire_checks.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace tofguard {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

discrepancy_t valid_discrepancy() {
  discrepancy_t d{};
  d.utime = 1'700'000'000'000'000;
  d.seq = 3;
  d.camera_id = "cam";
  d.usable = true;
  d.invalid_fraction = 0.1f;
  d.mismatch_fraction = 0.2f;
  d.p95_abs_dis_mm = 40;
  d.num_robot_links = 1;
  d.num_links = 2;
  d.link_name = {"link1", "floor"};
  d.link_compared = {10, 20};
  d.link_match = {8, 20};
  d.link_farther = {2, 0};
  d.link_nearer = {0, 0};
  d.link_invalid = {0, 0};
  d.link_median_dis_mm = {0, 0};
  return d;
}

// The first word of the problem: the field it names.
std::string field_of(const discrepancy_t& d) {
  const std::string problem = check_discrepancy(d);
  return problem.substr(0, problem.find(':'));
}

TEST(WireChecks, Discrepancy) {
  EXPECT_EQ(check_discrepancy(valid_discrepancy()), "");
  discrepancy_t d = valid_discrepancy();
  d.utime = 0;
  EXPECT_EQ(field_of(d), "utime");
  d = valid_discrepancy();
  d.seq = -1;
  EXPECT_EQ(field_of(d), "seq");
  d = valid_discrepancy();
  d.num_robot_links = 3;
  EXPECT_EQ(field_of(d), "num_robot_links");
  d = valid_discrepancy();
  d.invalid_fraction = kNaN;
  EXPECT_EQ(field_of(d), "invalid_fraction");
  for (float bad : {-0.1f, 1.5f, kNaN}) {
    d = valid_discrepancy();
    d.mismatch_fraction = bad;
    EXPECT_EQ(field_of(d), "mismatch_fraction") << bad;
  }
  for (float bad : {-1.0f, kNaN, std::numeric_limits<float>::infinity()}) {
    d = valid_discrepancy();
    d.p95_abs_dis_mm = bad;
    EXPECT_EQ(field_of(d), "p95_abs_dis_mm") << bad;
  }
  d = valid_discrepancy();
  d.link_match[1] = 21;
  EXPECT_EQ(field_of(d), "link_compared[1]");
  d = valid_discrepancy();
  d.near_arm_area_m2 = kNaN;
  EXPECT_EQ(field_of(d), "near_arm_area_m2 / largest_blob_area_m2");
}

TEST(WireChecks, Heartbeat) {
  heartbeat_t hb{};
  EXPECT_EQ(check_heartbeat(hb), "process: expected a process name, got an empty string");
  hb.process = "tofguard-camera";
  EXPECT_EQ(check_heartbeat(hb), "");
}

TEST(WireChecks, SimCameraFault) {
  sim_camera_fault_t f{};
  f.kind = sim_camera_fault_t::CLEAR;
  EXPECT_EQ(check_sim_camera_fault(f), "");
  f.kind = 7;
  EXPECT_EQ(check_sim_camera_fault(f), "kind: expected 0..4, got 7");
  f.kind = sim_camera_fault_t::FROZEN_IMAGE;
  EXPECT_NE(check_sim_camera_fault(f), "");  // a fault needs a duration
  f.duration_s = 2;
  EXPECT_EQ(check_sim_camera_fault(f), "");
  f.object_position_m[1] = std::nan("");
  EXPECT_EQ(check_sim_camera_fault(f), "vectors: expected finite numbers");
  f.object_position_m[1] = 0;
  f.kind = sim_camera_fault_t::INTRUDING_OBJECT;
  EXPECT_EQ(check_sim_camera_fault(f), "object_size_m: expected 3 sizes > 0");
}

TEST(WireChecks, SimJointFault) {
  sim_joint_fault_t f{};
  f.joint = "a4";
  f.offset = 0.1745;
  EXPECT_EQ(check_sim_joint_fault(f), "");
  f.offset = std::nan("");
  EXPECT_NE(check_sim_joint_fault(f), "");
  f.offset = 0;
  f.joint = "";
  EXPECT_NE(check_sim_joint_fault(f), "");
}

}  // namespace
}  // namespace tofguard
