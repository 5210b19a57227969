// The motion estimator on frames of the simulated ToF camera: encoder
// offsets on each joint, camera pose errors, an object beside the arm.
#include "tofguard/estimator/motion_estimator.hpp"

#include <gtest/gtest.h>

#include <iostream>

#include "estimator_test_support.hpp"
#include "tofguard/estimator/estimate_message.hpp"
#include "tofguard/risk/estimate_finding.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::estimator {
namespace {

using test::deg;
using test::to_deg;

// What tofguard-risk makes of the estimate (risk.estimate in sim.yaml:
// significant beyond 3 sigma and 2 degrees): the estimate as published,
// then classify_estimate. The one rule that decides whether an estimate
// names a joint or the camera; the tests judge the estimator by it.
risk::FrameFinding risk_finding(const EstimateResult& r, const deployment::Config& config,
                                bool near_arm_evidence = false) {
  EstimateContext context;
  context.utime = 1;
  context.camera_id = config.camera.id;
  context.frame_id = config.camera.pose.frame_id;
  context.frame_from_optical = test::pose_of(config.camera.pose);
  risk::EstimateContext risk_context;
  risk_context.near_arm_evidence = near_arm_evidence;
  return risk::classify_estimate(to_message(r, context), config.risk, risk_context);
}

class MotionEstimatorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    config_ = new deployment::Config(test::sim_config());
    frames_ = new tofguard::test::SimulatedFrames(*config_);
  }
  static void TearDownTestSuite() {
    delete frames_;
    delete config_;
  }
  static EstimatorOptions options() {
    EstimatorOptions o;
    o.noise.sigma_at_0m_mm = config_->discrepancy.noise_sigma_at_0m_mm;
    o.noise.sigma_per_m2_mm = config_->discrepancy.noise_sigma_per_m2_mm;
    return o;
  }
  static deployment::Config* config_;
  static tofguard::test::SimulatedFrames* frames_;
};
deployment::Config* MotionEstimatorTest::config_ = nullptr;
tofguard::test::SimulatedFrames* MotionEstimatorTest::frames_ = nullptr;

// The frames of an estimate with an encoder offset on `joint`
// (SimulatedFrames::frames_with_offset): the sim camera where configured.
std::vector<EstimatorFrame> frames_with_offset(tofguard::test::SimulatedFrames* frames,
                                               const deployment::Config& config,
                                               const robot_model::JointPositions& truth,
                                               const std::string& joint, double offset_rad, int num_frames,
                                               uint64_t* index) {
  return frames->frames_with_offset(truth, test::pose_of(config.camera.pose), config.camera.intrinsics, joint,
                                    offset_rad, num_frames, index);
}

// Encoder offsets of 5, 10 and 20 degrees on each joint in turn (the
// joint reports more than it is at), arm in the side-reach pose where every
// link is seen, each estimate made of 3 frames like tofguard-estimator's.
// Target (docs/estimator.md): the suspect is right in >= 95 % of the cases and the estimated
// offset within 1.5 degrees or 25 %. Measured (2026-11-22, 3 frames):
// suspect right 21/21, offset accurate 21/21 (largest error 1.0 degree,
// a5); see docs/estimator.md for single frames. The suspect is the joint
// tofguard-risk's rules (classify_estimate) name.
TEST_F(MotionEstimatorTest, EncoderOffsets) {
  MotionEstimator estimator(frames_->scene(), &frames_->renderer(), options());
  const int num_frames = config_->estimator.frames_per_estimate;
  ASSERT_EQ(num_frames, 3);
  uint64_t index = 0;
  int right = 0, accurate = 0, cases = 0;
  double largest_error_deg = 0;
  for (const char* joint : {"a1", "a2", "a3", "a4", "a5", "a6", "a7"}) {
    for (double offset_deg : {5.0, 10.0, 20.0}) {
      const EstimateResult r = estimator.estimate(frames_with_offset(
          frames_, *config_, test::side_reach_pose(), joint, deg(offset_deg), num_frames, &index));
      ASSERT_TRUE(r.usable) << r.unusable_reason;
      EXPECT_EQ(r.num_frames, num_frames);
      ++cases;
      const int k = joint[1] - '1';
      const double error_deg = to_deg(r.joints[k].offset()) + offset_deg;
      const risk::FrameFinding finding = risk_finding(r, *config_);
      const bool is_right = finding.cause == tofguard::risk_t::CAUSE_JOINT_ERROR && finding.suspect == joint;
      const bool is_accurate = std::abs(error_deg) <= std::max(1.5, 0.25 * offset_deg);
      right += is_right;
      accurate += is_accurate;
      if (!is_right) std::cout << "  risk: " << finding.detail << " (converged " << r.converged << ")\n";
      largest_error_deg = std::max(largest_error_deg, std::abs(error_deg));
      std::cout << joint << " +" << offset_deg << " deg: estimated " << to_deg(r.joints[k].offset())
                << " (sigma " << to_deg(r.joints[k].sigma) << ")"
                << (is_right ? ", suspect right" : ", SUSPECT WRONG") << (is_accurate ? "" : ", INACCURATE")
                << "; iterations " << r.iterations << ", residual " << r.residual_before_m * 1000 << " -> "
                << r.residual_after_m * 1000 << " mm, " << r.compute_us / 1000 << " ms\n";
    }
  }
  std::cout << "suspect right " << right << ", offset accurate " << accurate << " of " << cases
            << ", largest offset error " << largest_error_deg << " deg\n";
  EXPECT_GE(right, 20);     // target: >= 95 %
  EXPECT_GE(accurate, 20);  // target: >= 95 %
}

// One frame alone (the library's estimate(frame)): the same cases, for the
// record of what a single frame achieves (docs/estimator.md). The camera's
// mixed pixels and noise leave the wrist joints (a5, a7) a little over a
// degree off on some frames; the suspect is still right.
TEST_F(MotionEstimatorTest, EncoderOffsetsFromOneFrame) {
  MotionEstimator estimator(frames_->scene(), &frames_->renderer(), options());
  uint64_t index = 500;
  int right = 0, accurate = 0, cases = 0;
  for (const char* joint : {"a1", "a2", "a3", "a4", "a5", "a6", "a7"}) {
    for (double offset_deg : {5.0, 10.0, 20.0}) {
      const EstimateResult r = estimator.estimate(frames_with_offset(
          frames_, *config_, test::side_reach_pose(), joint, deg(offset_deg), 1, &index)[0]);
      ASSERT_TRUE(r.usable) << r.unusable_reason;
      ++cases;
      const int k = joint[1] - '1';
      const double error_deg = to_deg(r.joints[k].offset()) + offset_deg;
      const risk::FrameFinding finding = risk_finding(r, *config_);
      right += finding.cause == tofguard::risk_t::CAUSE_JOINT_ERROR && finding.suspect == joint;
      accurate += std::abs(error_deg) <= std::max(1.5, 0.25 * offset_deg);
      std::cout << joint << " +" << offset_deg << " deg, one frame: estimated "
                << to_deg(r.joints[k].offset()) << " (sigma " << to_deg(r.joints[k].sigma) << ")\n";
    }
  }
  std::cout << "one frame: suspect right " << right << ", offset accurate " << accurate << " of " << cases
            << "\n";
  EXPECT_GE(right, 18);
  EXPECT_GE(accurate, 18);
}

// The reported camera pose is off by 5 cm or 3 degrees; the joints are
// right. Target: the correction within 1 cm and 0.5 degrees, no joint
// offset significant. Measured (2026-11-22): 2.0..5.5 mm and 0.03..0.29
// degrees.
TEST_F(MotionEstimatorTest, CameraPoseErrors) {
  MotionEstimator estimator(frames_->scene(), &frames_->renderer(), options());
  const Eigen::Isometry3d truth_camera = test::pose_of(config_->camera.pose);
  const Intrinsics& in = config_->camera.intrinsics;
  struct Case {
    const char* name;
    Eigen::Vector3d translation_world_m;
    Eigen::Vector3d rotation_optical_rad;
  };
  const std::vector<Case> cases = {
      {"5 cm forward", {0.05, 0, 0}, Eigen::Vector3d::Zero()},
      {"5 cm left", {0, 0.05, 0}, Eigen::Vector3d::Zero()},
      {"5 cm down", {0, 0, -0.05}, Eigen::Vector3d::Zero()},
      {"3 deg tilt", Eigen::Vector3d::Zero(), {deg(3), 0, 0}},
      {"3 deg pan", Eigen::Vector3d::Zero(), {0, deg(3), 0}},
      {"3 deg roll", Eigen::Vector3d::Zero(), {0, 0, deg(3)}},
  };
  uint64_t index = 100;
  for (const Case& c : cases) {
    for (const robot_model::JointPositions& joints : {test::reach_pose(), test::side_reach_pose()}) {
      EstimatorFrame frame;
      frame.intrinsics = in;
      frame.depth_m = frames_->capture(joints, truth_camera, in, ++index);
      frame.reported_joints = joints;
      Eigen::Isometry3d reported = truth_camera;
      reported.translation() += c.translation_world_m;
      if (c.rotation_optical_rad.norm() > 0) {
        reported.linear() = reported.linear() * Eigen::AngleAxisd(c.rotation_optical_rad.norm(),
                                                                  c.rotation_optical_rad.normalized())
                                                    .toRotationMatrix();
      }
      frame.world_from_optical = reported;
      const EstimateResult r = estimator.estimate(frame);
      ASSERT_TRUE(r.usable) << r.unusable_reason;
      // What the correction should be: reported optical <- true optical.
      const Eigen::Isometry3d expected = reported.inverse() * truth_camera;
      const Eigen::Isometry3d error = expected.inverse() * r.correction;
      const double error_mm = error.translation().norm() * 1000;
      const double error_deg = to_deg(Eigen::AngleAxisd(error.linear()).angle());
      std::cout << c.name << ": error " << error_mm << " mm " << error_deg << " deg, conv " << r.converged
                << " it " << r.iterations << " sigma " << r.correction_translation_sigma_m * 1000 << " mm "
                << to_deg(r.correction_rotation_sigma_rad) << " deg\n";
      EXPECT_LT(error_mm, 10.0) << c.name;
      EXPECT_LT(error_deg, 0.5) << c.name;
      // Target: classified as calibration (tofguard-risk's rules), no
      // joint offset significant (classify_estimate would add "joint ...
      // also off by").
      const risk::FrameFinding finding = risk_finding(r, *config_);
      EXPECT_EQ(finding.cause, tofguard::risk_t::CAUSE_CALIBRATION_ERROR) << c.name << ": " << finding.detail;
      EXPECT_EQ(finding.detail.find(" also off by "), std::string::npos) << c.name << ": " << finding.detail;
    }
  }
}

// A box beside the arm (the simulated camera's intruding object) must not
// pull the estimate: every joint's estimate moves by less than 1 degree
// (the target). Measured (2026-11-22): at most 0.84 degrees (a6, box beside
// link4).
TEST_F(MotionEstimatorTest, ObjectBesideTheArm) {
  MotionEstimator estimator(frames_->scene(), &frames_->renderer(), options());
  const Eigen::Isometry3d camera = test::pose_of(config_->camera.pose);
  const Intrinsics& in = config_->camera.intrinsics;
  const robot_model::JointPositions joints = test::side_reach_pose();
  const robot_model::LinkPoses poses = robot_model::forward_kinematics(frames_->scene(), joints);
  uint64_t index = 200;
  for (const char* link : {"link4", "link6", "gripper"}) {
    // A 12 cm box whose side is 10 cm from the link's frame origin, seen
    // beside the arm (to the camera's right of it).
    const Eigen::Vector3d at = poses.world_from_link[frames_->scene().find_link(link)].translation();
    const Eigen::Vector3d right_in_world = camera.linear() * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d center = at + right_in_world * 0.16;
    const std::vector<renderer::ExtraObject> box = {renderer::ExtraObject::box(
        Eigen::Vector3d(0.12, 0.12, 0.12), Eigen::Isometry3d(Eigen::Translation3d(center)))};
    ++index;
    EstimatorFrame clear;
    clear.intrinsics = in;
    clear.depth_m = frames_->capture(joints, camera, in, index);
    clear.reported_joints = joints;
    clear.world_from_optical = camera;
    EstimatorFrame with_box = clear;
    with_box.depth_m = frames_->capture(joints, camera, in, index, box);
    const EstimateResult a = estimator.estimate(clear);
    const EstimateResult b = estimator.estimate(with_box);
    ASSERT_TRUE(a.usable) << a.unusable_reason;
    ASSERT_TRUE(b.usable) << b.unusable_reason;
    std::cout << link << ": ";
    for (size_t k = 0; k < a.joints.size(); ++k) {
      const double moved_deg = to_deg(std::abs(b.joints[k].estimated - a.joints[k].estimated));
      std::cout << a.joints[k].name << " " << moved_deg << "  ";
      EXPECT_LT(moved_deg, 1.0) << "box beside " << link << ": joint " << a.joints[k].name;
    }
    std::cout << " camera moved " << (a.correction.inverse() * b.correction).translation().norm() * 1000
              << " mm\n";
    // Target: the cause is UNKNOWN_OBJECT. The estimate names no joint and
    // no camera error; with the discrepancy's evidence of nearer surfaces
    // near the arm (what the object frame's discrepancy_t carries),
    // tofguard-risk's estimate rule calls it an unknown object.
    const risk::FrameFinding alone = risk_finding(b, *config_);
    EXPECT_NE(alone.cause, tofguard::risk_t::CAUSE_JOINT_ERROR) << link << ": " << alone.detail;
    EXPECT_NE(alone.cause, tofguard::risk_t::CAUSE_CALIBRATION_ERROR) << link << ": " << alone.detail;
    EXPECT_EQ(risk_finding(b, *config_, /*near_arm_evidence=*/true).cause,
              tofguard::risk_t::CAUSE_UNKNOWN_OBJECT)
        << link;
  }
}

}  // namespace
}  // namespace tofguard::estimator
