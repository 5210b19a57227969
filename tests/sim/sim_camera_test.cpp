// The simulated camera's logic with a fake renderer: true joint states
// interpolated at the capture time, determinism, and the injected faults.
// (The interpolation itself is robot_state::JointHistory's, tested there.)
#include "tofguard/sim/sim_camera.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "sim_test_config.hpp"
#include "tofguard/deployment/config.hpp"

namespace tofguard::sim {
namespace {

// A wall at 2 m; joint a1 moves a 1 m-deep block sideways: its left
// column is 40 + 40 * a1.
class FakeRenderer : public SceneRenderer {
 public:
  RenderedDepth render(const std::map<std::string, double>& joints, const CameraPose& pose,
                       const Intrinsics& in, const std::vector<SimBox>& boxes,
                       const std::vector<RegionShape>& /*user*/) override {
    last_joints = joints;
    last_pose = pose;
    last_boxes = boxes;
    ++calls;
    RenderedDepth out;
    if (fail) {
      out.unusable_reason = "joint a1 missing";
      return out;
    }
    out.usable = true;
    out.depth_m.assign(static_cast<size_t>(in.width) * in.height, 2.0f);
    const int left = 40 + static_cast<int>(40 * joints.at("a1"));
    for (int v = 40; v < 100; ++v)
      for (int u = left; u < left + 30; ++u) out.depth_m[static_cast<size_t>(v) * in.width + u] = 1.0f;
    return out;
  }
  std::map<std::string, double> last_joints;
  CameraPose last_pose;
  std::vector<SimBox> last_boxes;
  int calls = 0;
  bool fail = false;
};

constexpr int64_t kT0 = 1700000000000000;  // some wall time, microseconds

deployment::CameraSection camera_config() {
  deployment::CameraSection c;
  c.id = "test-cam";
  c.source = "sim";
  c.rate_hz = 30;
  c.intrinsics = sim_test::test_intrinsics();
  c.pose.frame_id = "world";
  c.pose.translation_m = Eigen::Vector3d(0, 0, 1.5);
  c.sim = sim_test::test_sim_config();
  return c;
}

TEST(SimulatedCamera, RendersAtTheTrueJointsOfTheCaptureTime) {
  FakeRenderer renderer;
  SimulatedCamera sim(camera_config(), camera_config().sim, &renderer, kT0);
  auto frame = sim.capture(kT0, 0);
  EXPECT_EQ(frame.outcome, SimulatedCamera::Frame::Outcome::kNoJointState);
  EXPECT_EQ(renderer.calls, 0);
  sim.add_true_joint_state(kT0, {"a1"}, {0.0});
  sim.add_true_joint_state(kT0 + 10000, {"a1"}, {0.5});
  frame = sim.capture(kT0 + 4000, 1);
  ASSERT_EQ(frame.outcome, SimulatedCamera::Frame::Outcome::kImage) << frame.why;
  EXPECT_DOUBLE_EQ(renderer.last_joints.at("a1"), 0.2);
  // The block's left edge at column 48; the error model was applied: the
  // block reads 1 m + e(r), the wall 2 m + e(r), not the rendered values.
  const int w = 176;
  EXPECT_GT(frame.image.depth_m[70 * w + 60], 1.05f);
  EXPECT_LT(frame.image.depth_m[70 * w + 60], 1.25f);
  EXPECT_GT(frame.image.depth_m[70 * w + 120], 2.0f);
  EXPECT_FALSE(frame.image.amplitude.empty());
  renderer.fail = true;
  frame = sim.capture(kT0 + 5000, 2);
  EXPECT_EQ(frame.outcome, SimulatedCamera::Frame::Outcome::kRenderFailed);
  EXPECT_EQ(frame.why, "render failed: joint a1 missing");
}

TEST(SimulatedCamera, SameSeedSameFrames) {
  FakeRenderer r1, r2;
  SimulatedCamera a(camera_config(), camera_config().sim, &r1, kT0);
  SimulatedCamera b(camera_config(), camera_config().sim, &r2, kT0);
  for (SimulatedCamera* s : {&a, &b}) s->add_true_joint_state(kT0, {"a1"}, {0.3});
  const auto fa = a.capture(kT0 + 1000, 7);
  const auto fb = b.capture(kT0 + 1000, 7);
  ASSERT_EQ(fa.outcome, SimulatedCamera::Frame::Outcome::kImage);
  EXPECT_EQ(fa.image.depth_m, fb.image.depth_m);
  EXPECT_EQ(fa.image.amplitude, fb.image.amplitude);
  EXPECT_NE(fa.image.depth_m, a.capture(kT0 + 1000, 8).image.depth_m);
}

// The error model's warm-up drift runs on the camera's own time since it
// started: the same frame index (the same noise) 5 min later reads the
// drift's growth farther everywhere.
TEST(SimulatedCamera, WarmsUpFromItsStart) {
  deployment::CameraSection config = camera_config();
  config.sim.residual.warmup_drift_mm = 6;
  config.sim.residual.warmup_time_constant_s = 300;
  FakeRenderer renderer;
  SimulatedCamera sim(config, config.sim, &renderer, kT0);
  constexpr int64_t kLater = kT0 + 300000000;  // 5 min
  sim.add_true_joint_state(kT0, {"a1"}, {0.3});
  const auto start = sim.capture(kT0, 7);
  sim.add_true_joint_state(kLater, {"a1"}, {0.3});
  const auto later = sim.capture(kLater, 7);
  ASSERT_EQ(later.outcome, SimulatedCamera::Frame::Outcome::kImage) << later.why;
  const camera::RadialToZ to_z(config.intrinsics);
  const size_t centre = 72 * 176 + 87;  // Z/r = 1 at the principal point
  ASSERT_GT(start.image.depth_m[centre], 0.0f);
  EXPECT_NEAR((later.image.depth_m[centre] - start.image.depth_m[centre]) / to_z.factor(87, 72),
              6e-3 * (1 - std::exp(-1.0)), 1e-6);
}

TEST(SimulatedCamera, ConfigFaultsStallFreezeDriftAndIntrude) {
  deployment::CameraSection config = camera_config();
  SimCameraFaultSettings stall, frozen, drift, object;
  stall.kind = "stall";
  stall.start_us = 1000000;
  stall.duration_us = 500000;
  frozen.kind = "frozen_image";
  frozen.start_us = 2000000;
  frozen.duration_us = 1000000;
  drift.kind = "pose_drift";
  drift.start_us = 4000000;
  drift.duration_us = 2000000;
  drift.drift_translation_m_per_s = Eigen::Vector3d(0.01, 0, 0);
  drift.drift_rotation_rad_per_s = Eigen::Vector3d(0, 0, 0.1);
  object.kind = "intruding_object";
  object.start_us = 7000000;
  object.duration_us = 1000000;
  object.object_size_m = Eigen::Vector3d(0.1, 0.2, 0.3);
  object.object_position_m = Eigen::Vector3d(1, 0, 0.5);
  object.object_velocity_m_per_s = Eigen::Vector3d(0, -0.5, 0);
  config.sim.faults = {stall, frozen, drift, object};
  FakeRenderer renderer;
  SimulatedCamera sim(config, config.sim, &renderer, kT0);
  auto at = [&](double s) { return kT0 + static_cast<int64_t>(s * 1e6); };
  // The arm's true states arrive at 100 Hz up to each capture.
  double joints_until_s = 0;
  auto capture = [&](double s, uint64_t index) {
    for (; joints_until_s <= s + 0.01; joints_until_s += 0.01) {
      sim.add_true_joint_state(at(joints_until_s), {"a1"}, {joints_until_s / 10});
    }
    return sim.capture(at(s), index);
  };

  EXPECT_EQ(capture(0.5, 0).outcome, SimulatedCamera::Frame::Outcome::kImage);
  EXPECT_EQ(capture(1.2, 1).outcome, SimulatedCamera::Frame::Outcome::kStalled);
  EXPECT_EQ(capture(1.6, 2).outcome, SimulatedCamera::Frame::Outcome::kImage);
  const auto before_freeze = capture(1.9, 3);
  const int calls = renderer.calls;
  const auto frozen_frame = capture(2.5, 4);  // the arm moved, the image did not
  EXPECT_TRUE(frozen_frame.frozen);
  EXPECT_EQ(frozen_frame.image.depth_m, before_freeze.image.depth_m);
  EXPECT_EQ(renderer.calls, calls);
  EXPECT_FALSE(capture(3.1, 5).frozen);

  // Drift: 1 s into it, 1 cm along x and 0.1 rad about the optical z axis;
  // after it ends the camera stays where it drifted to.
  EXPECT_TRUE(sim.true_pose(at(3.9)).translation_m.isApprox(Eigen::Vector3d(0, 0, 1.5)));
  capture(5.0, 6);
  EXPECT_NEAR(renderer.last_pose.translation_m.x(), 0.01, 1e-9);
  EXPECT_NEAR(Eigen::AngleAxisd(renderer.last_pose.rotation).angle(), 0.1, 1e-9);
  EXPECT_NEAR(sim.true_pose(at(9.0)).translation_m.x(), 0.02, 1e-9);

  EXPECT_TRUE(sim.boxes(at(6.9)).empty());
  capture(7.5, 7);
  ASSERT_EQ(renderer.last_boxes.size(), 1u);
  EXPECT_TRUE(renderer.last_boxes[0].center_m.isApprox(Eigen::Vector3d(1, -0.25, 0.5)));
  EXPECT_TRUE(renderer.last_boxes[0].size_m.isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_TRUE(sim.boxes(at(8.0)).empty());
}

TEST(SimulatedCamera, RunTimeFaultsAndClear) {
  FakeRenderer renderer;
  SimulatedCamera sim(camera_config(), camera_config().sim, &renderer, kT0);
  sim.add_true_joint_state(kT0, {"a1"}, {0.0});
  ActiveSimFault stall;
  stall.fault.kind = "stall";
  stall.start_utime = kT0 + 1000;
  stall.end_utime = kT0 + 1000000;
  sim.inject(stall);
  EXPECT_EQ(sim.capture(kT0 + 2000, 0).outcome, SimulatedCamera::Frame::Outcome::kStalled);
  sim.clear_faults(kT0 + 3000);
  EXPECT_EQ(sim.capture(kT0 + 4000, 1).outcome, SimulatedCamera::Frame::Outcome::kImage);
}

TEST(SimulatedCamera, PanTiltHeadTurnsTheCameraAndReportsItsReading) {
  deployment::CameraSection config = camera_config();
  // Looking along world x from 1.5 m up.
  config.pose.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ())) *
                         Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()));
  FakeRenderer renderer;
  SimulatedCamera fixed(config, config.sim, &renderer, kT0);
  EXPECT_FALSE(fixed.reported_pose(kT0).has_value()) << "no head, no reading";

  config.sim.pan_tilt_enabled = true;
  config.sim.pan_amplitude_rad = 10 * M_PI / 180;
  config.sim.pan_period_s = 4;
  config.sim.tilt_amplitude_rad = 4 * M_PI / 180;
  config.sim.tilt_period_s = 8;
  SimulatedCamera sim(config, config.sim, &renderer, kT0);
  // 1 s in: pan at its peak (+10 deg), tilt at sin(pi/4) * 4 deg.
  const int64_t t = kT0 + 1'000'000;
  const CameraPose truth = sim.true_pose(t);
  const Eigen::Vector3d forward = truth.rotation * Eigen::Vector3d::UnitZ();
  const double tilt = 4 * std::sin(M_PI / 4) * M_PI / 180;
  // Panned left (towards +y) by 10 deg, tilted up by `tilt`.
  EXPECT_NEAR(std::atan2(forward.y(), forward.x()), 10 * M_PI / 180, 1e-9);
  EXPECT_NEAR(std::asin(forward.z()), tilt, 1e-9);
  EXPECT_EQ(truth.translation_m, config.pose.translation_m);
  // Without a fault the head reports the truth.
  ASSERT_TRUE(sim.reported_pose(t).has_value());
  EXPECT_LT(sim.reported_pose(t)->rotation.angularDistance(truth.rotation), 1e-12);
  // The frame is rendered from the true pose.
  sim.add_true_joint_state(t - 10'000, {"a1"}, {0.0});
  sim.add_true_joint_state(t + 10'000, {"a1"}, {0.0});
  ASSERT_EQ(sim.capture(t, 0).outcome, SimulatedCamera::Frame::Outcome::kImage);
  EXPECT_LT(renderer.last_pose.rotation.angularDistance(truth.rotation), 1e-12);

  // A pan offset of 3 deg: the reading is off, the truth unchanged.
  ActiveSimFault offset;
  offset.fault.kind = "pan_tilt_offset";
  offset.fault.pan_offset_rad = 3 * M_PI / 180;
  offset.start_utime = kT0;
  offset.end_utime = kT0 + 10'000'000;
  sim.inject(offset);
  const CameraPose reported = *sim.reported_pose(t);
  const Eigen::Vector3d reported_forward = reported.rotation * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(std::atan2(reported_forward.y(), reported_forward.x()), 13 * M_PI / 180, 1e-9);
  EXPECT_NEAR(std::asin(reported_forward.z()), tilt, 1e-9);
  EXPECT_LT(sim.true_pose(t).rotation.angularDistance(truth.rotation), 1e-12);
}

}  // namespace
}  // namespace tofguard::sim
