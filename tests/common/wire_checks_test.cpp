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

// With the evidence fields filled.
discrepancy_t discrepancy_with_evidence() {
  discrepancy_t d = valid_discrepancy();
  d.evidence_available = true;
  d.num_link_bias = 2;
  d.link_bias_mm = {1.5f, -0.5f};
  d.link_bias_sigma_mm = {0.8f, 0.2f};
  d.camera_fit_pixels = 20;
  for (int k = 0; k < 6; ++k) d.camera_information[7 * k] = 1e6;
  d.static_chi2 = 18;
  for (int r = 0; r < 4; ++r) {
    d.camera_region_fit_pixels[r] = 5;
    for (int a = 0; a < 6; ++a) d.camera_region_information[6 * r + a] = 2.5e5;
  }
  d.num_joints = 2;
  d.joint_name = {"a1", "a2"};
  d.joint_fit_pixels = {10, 4};
  d.joint_score = {100, -3};
  d.joint_information = {1e5, 2e3};
  d.joint_naming_score = {90, -2};
  d.joint_naming_information = {9e4, 2e3};
  d.joint_static_bound = {0, 0};
  d.robot_fit_pixels = 10;
  d.robot_chi2 = 9;
  d.search_points = 10;
  d.joint_search_offset = {0.05, -0.002};
  d.joint_search_gain = {40, 0};
  d.camera_search_static_points = 12;
  d.camera_search_axis = 3;
  d.camera_search_offset = -0.01;
  d.camera_search_gain = 55;
  d.joint_reach_m = {0.8, 0.5};
  return d;
}

TEST(WireChecks, DiscrepancyEvidence) {
  EXPECT_EQ(check_discrepancy(discrepancy_with_evidence()), "");
  discrepancy_t d = discrepancy_with_evidence();
  d.num_link_bias = 1;
  d.link_bias_mm.resize(1);
  d.link_bias_sigma_mm.resize(1);
  EXPECT_EQ(field_of(d), "num_link_bias");
  d = discrepancy_with_evidence();
  d.link_bias_mm[1] = kNaN;
  EXPECT_EQ(field_of(d), "link_bias_mm[1]");
  d = discrepancy_with_evidence();
  d.link_bias_sigma_mm[0] = -1;
  EXPECT_EQ(field_of(d), "link_bias_sigma_mm[0]");
  d = discrepancy_with_evidence();
  d.camera_score[4] = std::nan("");
  EXPECT_EQ(field_of(d), "camera_score[4]");
  d = discrepancy_with_evidence();
  d.camera_information[14] = -1;
  EXPECT_EQ(field_of(d), "camera_information[14]");
  d = discrepancy_with_evidence();
  d.camera_correction[5] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(field_of(d), "camera_correction[5]");
  d = discrepancy_with_evidence();
  d.static_chi2 = -1;
  EXPECT_EQ(field_of(d), "static_chi2");
  d = discrepancy_with_evidence();
  d.camera_region_fit_pixels[3] = -1;
  EXPECT_EQ(field_of(d), "camera_region_fit_pixels[3]");
  d = discrepancy_with_evidence();
  d.camera_region_score[23] = kNaN;
  EXPECT_EQ(field_of(d), "camera_region_score[23]");
  d = discrepancy_with_evidence();
  d.camera_region_information[7] = -1;
  EXPECT_EQ(field_of(d), "camera_region_information[7]");
  d = discrepancy_with_evidence();
  d.joint_score.resize(1);
  EXPECT_EQ(field_of(d), "joint_score");
  d = discrepancy_with_evidence();
  d.joint_name[1] = "a1";
  EXPECT_EQ(field_of(d), "joint_name[1]");
  d = discrepancy_with_evidence();
  d.joint_information[0] = -2;
  EXPECT_EQ(field_of(d), "joint_information[0]");
  d = discrepancy_with_evidence();
  d.joint_naming_information.resize(1);
  EXPECT_EQ(field_of(d), "joint_naming_information");
  d = discrepancy_with_evidence();
  d.joint_naming_score[1] = kNaN;
  EXPECT_EQ(field_of(d), "joint_naming_score[1]");
  d = discrepancy_with_evidence();
  d.joint_naming_information[0] = -1;
  EXPECT_EQ(field_of(d), "joint_naming_information[0]");
  d = discrepancy_with_evidence();
  d.robot_chi2 = std::nan("");
  EXPECT_EQ(field_of(d), "robot_chi2");
  d = discrepancy_with_evidence();
  d.search_points = -1;
  EXPECT_EQ(field_of(d), "search_points");
  d = discrepancy_with_evidence();
  d.joint_search_gain.resize(3);
  EXPECT_EQ(field_of(d), "joint_search_gain");
  d = discrepancy_with_evidence();
  d.joint_search_offset[1] = kNaN;
  EXPECT_EQ(field_of(d), "joint_search_offset[1]");
  d = discrepancy_with_evidence();
  d.joint_search_gain[0] = -0.5;
  EXPECT_EQ(field_of(d), "joint_search_gain[0]");
  d = discrepancy_with_evidence();
  d.camera_search_axis = 6;
  EXPECT_EQ(field_of(d), "camera_search_axis");
  d = discrepancy_with_evidence();
  d.camera_search_gain = -1;
  EXPECT_EQ(field_of(d), "camera_search_gain");
  d = discrepancy_with_evidence();
  d.camera_search_offset = kNaN;
  EXPECT_EQ(field_of(d), "camera_search_offset");
  d = discrepancy_with_evidence();
  d.camera_search_static_points = -2;
  EXPECT_EQ(field_of(d), "camera_search_static_points");
  d = discrepancy_with_evidence();
  d.joint_static_bound[1] = -1;
  EXPECT_EQ(field_of(d), "joint_static_bound[1]");
  d = discrepancy_with_evidence();
  d.camera_region_static_bound[5] = kNaN;
  EXPECT_EQ(field_of(d), "camera_region_static_bound[5]");
  d = discrepancy_with_evidence();
  d.distance_offset_information = -1;
  EXPECT_EQ(field_of(d), "distance_offset_information");
}

TEST(WireChecks, DiscrepancyProtectiveField) {
  discrepancy_t d = discrepancy_with_evidence();
  d.field_available = true;
  d.field_bin_m = 0.01f;
  d.num_field_bins = 3;
  d.unexplained_area_within_m2 = {0, 0.001f, 0.001f};
  EXPECT_EQ(check_discrepancy(d), "");
  d.unexplained_area_within_m2 = {0, 0.001f, 0.0005f};  // cumulative areas never shrink
  EXPECT_EQ(field_of(d), "unexplained_area_within_m2[2]");
  d.unexplained_area_within_m2 = {0, 0.001f};
  EXPECT_EQ(field_of(d), "unexplained_area_within_m2");
  d.unexplained_area_within_m2 = {0, 0.001f, 0.001f};
  d.field_bin_m = 0;
  EXPECT_EQ(field_of(d), "field_bin_m");
  d = discrepancy_with_evidence();
  d.joint_reach_m[1] = -1;
  EXPECT_EQ(field_of(d), "joint_reach_m[1]");
}

// Two robot links and a floor; axes a1 (revolute) then a2 (prismatic).
link_labels_t labels_with_kinematics() {
  link_labels_t l{};
  l.utime = 1'700'000'000'000'000;
  l.seq = 1;
  l.camera_id = "cam";
  l.usable = true;
  l.width = 2;
  l.height = 1;
  l.num_robot_links = 2;
  l.num_links = 3;
  l.link_name = {"base", "link1", "floor"};
  l.num_pixels = 2;
  l.label = {1, 2};
  l.num_joints = 2;
  l.joint_name = {"a1", "a2"};
  l.num_axes = 2;
  l.axis_joint = {0, 1};
  l.axis_multiplier = {1, 1};
  l.axis_prismatic = {false, true};
  l.axis_origin_m = {{0, 0, 2}, {0.1, 0, 2}};
  l.axis_direction = {{0, 1, 0}, {0, 0, 1}};
  l.axis_parent = {-1, 0};
  l.num_link_axes = 2;
  l.link_axis = {-1, 1};
  return l;
}

std::string field_of(const link_labels_t& l) {
  const std::string problem = check_link_labels(l);
  return problem.substr(0, problem.find(':'));
}

TEST(WireChecks, LinkLabelsKinematics) {
  EXPECT_EQ(check_link_labels(labels_with_kinematics()), "");
  link_labels_t l = labels_with_kinematics();
  l.num_axes = 0;
  l.axis_joint.clear();
  l.axis_multiplier.clear();
  l.axis_prismatic.clear();
  l.axis_origin_m.clear();
  l.axis_direction.clear();
  l.axis_parent.clear();
  EXPECT_EQ(field_of(l), "num_link_axes") << "no axes, no link axes";
  l.num_link_axes = 0;
  l.link_axis.clear();
  EXPECT_EQ(check_link_labels(l), "") << "no kinematics at all";
  l = labels_with_kinematics();
  l.num_link_axes = 1;
  l.link_axis = {-1};
  EXPECT_EQ(field_of(l), "num_link_axes");
  l = labels_with_kinematics();
  l.axis_joint[1] = 2;
  EXPECT_EQ(field_of(l), "axis_joint[1]");
  l = labels_with_kinematics();
  l.axis_parent[0] = 0;
  EXPECT_EQ(field_of(l), "axis_parent[0]");
  l = labels_with_kinematics();
  l.axis_direction[0][1] = 1.01;
  EXPECT_EQ(field_of(l), "axis_direction[0]");
  l = labels_with_kinematics();
  l.axis_origin_m[1][2] = std::nan("");
  EXPECT_EQ(field_of(l), "axis_origin_m[1]");
  l = labels_with_kinematics();
  l.axis_multiplier[0] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(field_of(l), "axis_multiplier[0]");
  l = labels_with_kinematics();
  l.link_axis[0] = 2;
  EXPECT_EQ(field_of(l), "link_axis[0]");
  l = labels_with_kinematics();
  l.joint_name.pop_back();
  EXPECT_EQ(field_of(l), "joint_name");
}

TEST(WireChecks, LinkLabelsArmCover) {
  link_labels_t l = labels_with_kinematics();
  l.arm_cover_max_radius_m = 0.02;
  l.num_arm_spheres = 2;
  l.arm_sphere_link = {0, 1};
  l.arm_sphere_center_m = {{0, 0, 1}, {0.1, 0, 1}};
  l.arm_sphere_radius_m = {0.02f, 0.01f};
  EXPECT_EQ(check_link_labels(l), "");
  link_labels_t bad = l;
  bad.arm_sphere_link[1] = 2;  // the floor: not a robot link
  EXPECT_EQ(field_of(bad), "arm_sphere_link[1]");
  bad = l;
  bad.arm_sphere_radius_m[0] = 0.03f;  // beyond arm_cover_max_radius_m
  EXPECT_EQ(field_of(bad), "arm_sphere_radius_m[0]");
  bad = l;
  bad.arm_sphere_center_m[1][2] = std::nanf("");
  EXPECT_EQ(field_of(bad), "arm_sphere_center_m[1]");
  bad = l;
  bad.arm_sphere_radius_m.pop_back();
  EXPECT_EQ(field_of(bad), "arm_sphere_radius_m");
}

TEST(WireChecks, LinkLabelsOpticalPose) {
  link_labels_t l = labels_with_kinematics();
  // Not given: not read.
  l.world_from_optical[0] = std::nan("");
  EXPECT_EQ(check_link_labels(l), "");
  // A camera looking down (optical z along -z of the root frame) 1.8 m up.
  const double pose[12] = {1, 0, 0, 0.2, 0, -1, 0, 0.1, 0, 0, -1, 1.8};
  std::copy(pose, pose + 12, l.world_from_optical);
  l.optical_pose_given = true;
  EXPECT_EQ(check_link_labels(l), "");
  link_labels_t bad = l;
  bad.world_from_optical[3] = std::nan("");
  EXPECT_EQ(field_of(bad), "world_from_optical[3]");
  bad = l;
  bad.world_from_optical[0] = 1.01;  // not a rotation
  EXPECT_EQ(field_of(bad), "world_from_optical");
  bad = l;
  bad.world_from_optical[10] = 1;  // a reflection: det -1
  EXPECT_EQ(field_of(bad), "world_from_optical");
}

// Labels with two body regions, the face and a hand.
link_labels_t labels_with_regions() {
  link_labels_t l = labels_with_kinematics();
  l.num_body_regions = 2;
  l.body_region = {"face", "hand"};
  l.body_region_separation_m = {0.3f, 0.0f};
  l.body_region_envelope_m = {0.05f, 0.1f};
  return l;
}

TEST(WireChecks, LinkLabelsBodyRegions) {
  link_labels_t l = labels_with_regions();
  EXPECT_EQ(check_link_labels(l), "");
  link_labels_t bad = l;
  bad.body_region[1] = "hands";  // no such region
  EXPECT_EQ(field_of(bad), "body_region[1]");
  bad = l;
  bad.body_region[1] = "face";  // twice
  EXPECT_EQ(field_of(bad), "body_region[1]");
  bad = l;
  bad.body_region_separation_m[0] = -0.01f;
  EXPECT_EQ(field_of(bad), "body_region_separation_m[0]");
  bad = l;
  bad.body_region_separation_m[0] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(field_of(bad), "body_region_separation_m[0]");
  bad = l;
  bad.body_region_separation_m.pop_back();
  EXPECT_EQ(field_of(bad), "body_region_separation_m");
}

TEST(WireChecks, LinkLabelsOccupantShapes) {
  link_labels_t l = labels_with_regions();
  l.num_occupant_shapes = 2;
  l.occupant_shape_kind = {link_labels_t::SHAPE_BOX, link_labels_t::SHAPE_CYLINDER};
  l.occupant_shape_region = {0, 1};
  l.occupant_shape_center_m = {{0.1f, 0.2f, 1.5f}, {0.0f, 0.0f, 1.2f}};
  // The cylinder's axis along the optical x: a quarter turn about y.
  l.occupant_shape_rotation = {{1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 1, 0, 1, 0, -1, 0, 0}};
  l.occupant_shape_size_m = {{0.03f, 0.065f, 0.08f}, {0.04f, 0.13f, 0.0f}};
  EXPECT_EQ(check_link_labels(l), "");
  link_labels_t bad = l;
  bad.body_region_envelope_m.pop_back();
  EXPECT_EQ(field_of(bad), "body_region_envelope_m");
  bad = l;
  bad.body_region_envelope_m[1] = -0.1f;
  EXPECT_EQ(field_of(bad), "body_region_envelope_m[1]");
  bad = l;
  bad.occupant_shape_kind[1] = 3;
  EXPECT_EQ(field_of(bad), "occupant_shape_kind[1]");
  bad = l;
  bad.occupant_shape_region[0] = 2;  // only two regions
  EXPECT_EQ(field_of(bad), "occupant_shape_region[0]");
  bad = l;
  bad.occupant_shape_rotation[1] = {1, 0, 0, 0, 1, 0, 0, 0, -1};  // a reflection
  EXPECT_EQ(field_of(bad), "occupant_shape_rotation[1]");
  bad = l;
  bad.occupant_shape_size_m[0][2] = -0.01f;
  EXPECT_EQ(field_of(bad), "occupant_shape_size_m[0]");
  bad = l;
  bad.occupant_shape_center_m[0].pop_back();
  EXPECT_EQ(field_of(bad), "occupant_shape_center_m[0]");
  bad = l;
  bad.num_occupant_shapes = 3;
  EXPECT_EQ(field_of(bad), "occupant_shape_kind");
}

TEST(WireChecks, SpeedLimit) {
  speed_limit_t l{};
  l.max_arm_speed_m_s = 0.3;
  l.set_by = speed_limit_t::SET_BY_BODY_REGION;
  l.arm_speed_m_s = -1;
  l.valid_for_ms = 150;
  EXPECT_EQ(check_speed_limit(l), "");
  speed_limit_t bad = l;
  bad.max_arm_speed_m_s = std::nan("");
  EXPECT_EQ(check_speed_limit(bad).substr(0, 17), "max_arm_speed_m_s");
  bad = l;
  bad.set_by = 4;
  EXPECT_EQ(check_speed_limit(bad).substr(0, 6), "set_by");
  bad = l;
  bad.arm_speed_m_s = -0.5;
  EXPECT_EQ(check_speed_limit(bad).substr(0, 13), "arm_speed_m_s");
  bad = l;
  bad.valid_for_ms = 0;
  EXPECT_EQ(check_speed_limit(bad).substr(0, 12), "valid_for_ms");
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

TEST(WireChecks, SimControllerFault) {
  sim_controller_fault_t f{};
  f.utime = 1;
  f.ignore_speed_limit = true;
  EXPECT_EQ(check_sim_controller_fault(f), "");
  f.drive_joint = "a1";
  f.drive_rad_s = -1.5;
  EXPECT_EQ(check_sim_controller_fault(f), "");
  f.drive_rad_s = std::nan("");
  EXPECT_EQ(check_sim_controller_fault(f).substr(0, 11), "drive_rad_s");
  f.drive_joint = "";
  f.drive_rad_s = 0.5;  // a speed without a joint
  EXPECT_EQ(check_sim_controller_fault(f).substr(0, 11), "drive_rad_s");
  f.drive_rad_s = 0;
  f.utime = 0;
  EXPECT_EQ(check_sim_controller_fault(f).substr(0, 5), "utime");
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
