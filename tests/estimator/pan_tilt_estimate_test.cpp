// Pan-tilt: a camera on a pan-tilt head whose reading (what
// CAMERA_POSE reports) disagrees with where it really looks is flagged by
// the estimator's camera correction, and the risk classifier calls it a
// calibration error. The simulated camera's own pan-tilt model
// (sim's SimulatedCamera: true and reported pose at a time) with
// a pan_tilt_offset fault; frames from the simulated ToF camera (noise,
// mixed and invalid pixels, calibration).
#include <gtest/gtest.h>

#include <iostream>

#include "estimator_test_support.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/estimator/estimate_message.hpp"
#include "tofguard/estimator/estimator_process.hpp"
#include "tofguard/risk/estimate_finding.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/sim/sim_camera.hpp"

namespace tofguard::estimator {
namespace {

constexpr int64_t kSecond = 1'000'000;

// The head pans 10 degrees and tilts 4 about the configured pose; from 5 s
// on its reading is off by the given pan and tilt (radians).
deployment::Config pan_tilt_config(double pan_offset_rad, double tilt_offset_rad) {
  deployment::Config config = test::sim_config();
  sim::SimCameraSettings& sim = config.camera.sim;
  sim.pan_tilt_enabled = true;
  sim.pan_amplitude_rad = test::deg(10);
  sim.pan_period_s = 12;
  sim.tilt_amplitude_rad = test::deg(4);
  sim.tilt_period_s = 9;
  sim::SimCameraFaultSettings offset;
  offset.kind = "pan_tilt_offset";
  offset.start_us = 5000000;
  offset.duration_us = 1000000000;
  offset.pan_offset_rad = pan_offset_rad;
  offset.tilt_offset_rad = tilt_offset_rad;
  sim.faults = {offset};
  return config;
}

// The estimate of the frame captured `t_us` after the camera started, with
// the head's reading as the reported pose.
struct PanTiltCase {
  motion_estimate_t message;
  double reading_error_deg = 0;  // angle between true and reported pose
};

PanTiltCase estimate_at(const deployment::Config& config, tofguard::test::SimulatedFrames* frames,
                        int64_t t_us, uint64_t index) {
  sim::SimulatedCamera head(config.camera, config.camera.sim, nullptr, 0);
  const CameraPose true_pose = head.true_pose(t_us);
  const std::optional<CameraPose> reading = head.reported_pose(t_us);
  EXPECT_TRUE(reading.has_value());
  PanTiltCase out;
  out.reading_error_deg =
      test::to_deg(Eigen::AngleAxisd(true_pose.rotation.inverse() * reading->rotation).angle());
  const robot_model::JointPositions joints = test::side_reach_pose();
  EstimatorFrame frame;
  frame.intrinsics = config.camera.intrinsics;
  frame.depth_m = frames->capture(joints, test::pose_of(true_pose), frame.intrinsics, index);
  frame.reported_joints = joints;
  frame.world_from_optical = test::pose_of(*reading);
  MotionEstimator estimator(frames->scene(), &frames->renderer(),
                            options_from_settings(deployment::estimator_process_settings(config)));
  const EstimateResult result = estimator.estimate(frame);
  EstimateContext context;
  context.utime = t_us;
  context.seq = static_cast<int64_t>(index);
  context.camera_id = config.camera.id;
  context.frame_id = reading->frame_id;
  context.frame_from_optical = test::pose_of(*reading);
  out.message = to_message(result, context);
  return out;
}

double correction_deg(const motion_estimate_t& m) {
  const Eigen::Quaterniond q(m.correction_rotation[0], m.correction_rotation[1], m.correction_rotation[2],
                             m.correction_rotation[3]);
  return test::to_deg(Eigen::AngleAxisd(q.normalized()).angle());
}

// Before the fault the head turns (pan 10 deg at 3 s) and its reading is
// right: nothing to correct, no finding.
void expect_no_finding_before_the_fault(const deployment::Config& config,
                                        tofguard::test::SimulatedFrames* frames) {
  const PanTiltCase good = estimate_at(config, frames, 3 * kSecond, 1);
  EXPECT_NEAR(good.reading_error_deg, 0, 1e-9);
  ASSERT_TRUE(good.message.usable) << good.message.unusable_reason;
  EXPECT_LT(correction_deg(good.message), 0.5);
  const risk::FrameFinding none = risk::classify_estimate(good.message, config.risk);
  EXPECT_NE(none.cause, tofguard::risk_t::CAUSE_CALIBRATION_ERROR) << none.detail;
}

// After it the head's reading is 3 deg off: the correction finds it (at
// 8 s and 10 s, the head in other positions).
void expect_calibration_error_after_the_fault(const deployment::Config& config,
                                              tofguard::test::SimulatedFrames* frames) {
  uint64_t index = 2;
  for (int64_t t_us : {8 * kSecond, 10 * kSecond}) {
    const PanTiltCase bad = estimate_at(config, frames, t_us, index++);
    EXPECT_NEAR(bad.reading_error_deg, 3, 1e-6);
    ASSERT_TRUE(bad.message.usable) << bad.message.unusable_reason;
    std::cout << "reading 3 deg off at " << t_us / kSecond << " s: correction " << correction_deg(bad.message)
              << " deg, converged " << static_cast<int>(bad.message.converged) << "\n";
    EXPECT_NEAR(correction_deg(bad.message), 3, 0.5);
    const risk::FrameFinding flagged = risk::classify_estimate(bad.message, config.risk);
    EXPECT_EQ(flagged.cause, tofguard::risk_t::CAUSE_CALIBRATION_ERROR) << flagged.detail;
    EXPECT_EQ(flagged.detail.rfind("camera pose off by", 0), 0u) << flagged.detail;
  }
}

TEST(PanTilt, ATiltReadingThatDisagreesWithTheImageIsACalibrationError) {
  const deployment::Config config = pan_tilt_config(0, test::deg(3));
  tofguard::test::SimulatedFrames frames(config);
  expect_no_finding_before_the_fault(config, &frames);
  expect_calibration_error_after_the_fault(config, &frames);
}

// A pan error (a turn about the vertical) leaves the floor, the table top
// and the seat as they were: the wall behind the table is what shows it
// (docs/estimator.md).
TEST(PanTilt, APanReadingThatDisagreesWithTheImageIsACalibrationError) {
  const deployment::Config config = pan_tilt_config(test::deg(3), 0);
  tofguard::test::SimulatedFrames frames(config);
  expect_no_finding_before_the_fault(config, &frames);
  expect_calibration_error_after_the_fault(config, &frames);
}

}  // namespace
}  // namespace tofguard::estimator
