// Issue 7, pan-tilt: a camera on a pan-tilt head whose reading (what
// CAMERA_POSE reports) disagrees with where it really looks is flagged by
// the estimator's camera correction, and the risk classifier calls it a
// calibration error (issue 7, item 4). The simulated camera's own pan-tilt model
// (camera_driver's SimulatedCamera: true and reported pose at a time) with
// a pan_tilt_offset fault; frames from the simulated ToF camera (noise,
// mixed and invalid pixels, calibration).
#include <gtest/gtest.h>

#include "estimate_finding.hpp"
#include "estimate_message.hpp"
#include "estimator_process.hpp"
#include "estimator_test_support.hpp"
#include "sim_camera.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::estimator {
namespace {

constexpr int64_t kSecond = 1'000'000;

Config pan_tilt_config() {
  Config config = test::sim_config();
  SimCameraConfig& sim = config.camera.sim;
  sim.pan_tilt_enabled = true;
  sim.pan_amplitude_rad = test::deg(10);
  sim.pan_period_s = 12;
  sim.tilt_amplitude_rad = test::deg(4);
  sim.tilt_period_s = 9;
  SimCameraFaultConfig offset;
  offset.kind = "pan_tilt_offset";
  offset.start_s = 5;
  offset.duration_s = 1000;
  offset.tilt_offset_rad = test::deg(3);
  sim.faults = {offset};
  return config;
}

// The estimate of the frame captured `t_us` after the camera started, with
// the head's reading as the reported pose.
struct PanTiltCase {
  motion_estimate_t message;
  double reading_error_deg = 0;  // angle between true and reported pose
};

PanTiltCase estimate_at(const Config& config, testing::SimulatedFrames* frames, int64_t t_us, uint64_t index) {
  camera::SimulatedCamera head(config.camera, nullptr, 0);
  const CameraPose true_pose = head.true_pose(t_us);
  const std::optional<CameraPose> reading = head.reported_pose(t_us);
  EXPECT_TRUE(reading.has_value());
  PanTiltCase out;
  out.reading_error_deg =
      test::to_deg(Eigen::AngleAxisd(true_pose.rotation.inverse() * reading->rotation).angle());
  const renderer::JointPositions joints = test::side_reach_pose();
  EstimatorFrame frame;
  frame.intrinsics = config.camera.intrinsics;
  frame.depth_m = frames->capture(joints, test::pose_of(true_pose), frame.intrinsics, index);
  frame.reported_joints = joints;
  frame.world_from_optical = test::pose_of(*reading);
  MotionEstimator estimator(frames->scene(), &frames->renderer(), options_from_config(config));
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

TEST(PanTilt, AReadingThatDisagreesWithTheImageIsACalibrationError) {
  const Config config = pan_tilt_config();
  testing::SimulatedFrames frames(config);

  // Before the fault the head turns (pan 10 deg at 3 s) and its reading is
  // right: nothing to correct, no finding.
  const PanTiltCase good = estimate_at(config, &frames, 3 * kSecond, 1);
  EXPECT_NEAR(good.reading_error_deg, 0, 1e-9);
  ASSERT_TRUE(good.message.usable) << good.message.unusable_reason;
  EXPECT_LT(correction_deg(good.message), 0.5);
  const risk::FrameFinding none = risk::classify_estimate(good.message, config.risk);
  EXPECT_NE(none.cause, tofguard::risk_t::CAUSE_CALIBRATION_ERROR) << none.detail;

  // After it the head's tilt reading is 3 deg off: the correction finds it.
  // (A pan offset, a turn about the vertical, is not flagged by the
  // estimator in this scene: the environment's horizontal planes do not
  // see it and it trades against a1; docs/estimator.md, limits. The
  // discrepancy rules still stop the arm.)
  const PanTiltCase bad = estimate_at(config, &frames, 8 * kSecond, 2);
  EXPECT_NEAR(bad.reading_error_deg, 3, 1e-6);
  ASSERT_TRUE(bad.message.usable) << bad.message.unusable_reason;
  EXPECT_TRUE(bad.message.converged);
  EXPECT_NEAR(correction_deg(bad.message), 3, 0.5);
  const risk::FrameFinding flagged = risk::classify_estimate(bad.message, config.risk);
  EXPECT_EQ(flagged.cause, tofguard::risk_t::CAUSE_CALIBRATION_ERROR) << flagged.detail;
  EXPECT_EQ(flagged.detail.rfind("camera pose off by", 0), 0u) << flagged.detail;
}

}  // namespace
}  // namespace tofguard::estimator
