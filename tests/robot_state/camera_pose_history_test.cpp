// CameraPoseHistory: the camera pose at a frame's utime (interpolated,
// bounded extrapolation, unusable beyond), static poses and calibration
// steps held, frame changes.
#include "tofguard/robot_state/camera_pose_history.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace tofguard::robot_state {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;
constexpr double kDeg = M_PI / 180.0;

// The optical frame looking along world x, panned by `pan_deg` about z,
// at x = `x_m`.
CameraPose panned(double pan_deg, double x_m = 0.0, const std::string& frame = "world") {
  CameraPose p;
  p.frame_id = frame;
  p.translation_m = Eigen::Vector3d(x_m, 0, 1.5);
  p.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(pan_deg * kDeg, Eigen::Vector3d::UnitZ())) *
               Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()));
  return p;
}

double pan_deg_of(const CameraPose& p) {
  const Eigen::Quaterniond rest(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()));
  const Eigen::AngleAxisd pan(p.rotation * rest.inverse());
  return pan.angle() / kDeg * (pan.axis().z() < 0 ? -1 : 1);
}

TEST(CameraPoseHistory, StaticPoseUntilAPoseArrivesAndUnchangingPosesAreHeldForever) {
  CameraPoseHistory h(2'000'000, 40'000, 80'000);
  EXPECT_FALSE(h.at("cam", kT0).usable);
  EXPECT_EQ(h.at("cam", kT0).unusable_reason, "no camera pose for camera 'cam'");
  h.set_static("cam", panned(0));
  EXPECT_TRUE(h.at("cam", kT0).usable);
  // A calibration published (twice, the same) replaces it at any time.
  ASSERT_TRUE(h.add("cam", kT0, panned(0, 0.2)));
  ASSERT_TRUE(h.add("cam", kT0 + 1'000'000, panned(0, 0.2)));
  EXPECT_FALSE(h.moving("cam"));
  for (int64_t t : {kT0 - 60'000'000, kT0 + 500'000, kT0 + 600'000'000}) {
    const PoseAtTime p = h.at("cam", t);
    ASSERT_TRUE(p.usable);
    EXPECT_DOUBLE_EQ(p.pose.translation_m.x(), 0.2);
  }
  EXPECT_FALSE(h.add("cam", kT0 + 1'000'000, panned(5)));  // not newer
}

TEST(CameraPoseHistory, AMovingCameraIsInterpolatedAndExtrapolatedOnlyAsFarAsTheLimit) {
  CameraPoseHistory h(2'000'000, 40'000, 80'000);
  // Panning at 100 deg/s and moving 1 m/s along x.
  for (int i = 0; i <= 3; ++i) ASSERT_TRUE(h.add("cam", kT0 + i * 33'000, panned(3.3 * i, 0.033 * i)));
  EXPECT_TRUE(h.moving("cam"));
  // Between two poses: exact for this uniform motion.
  PoseAtTime p = h.at("cam", kT0 + 50'000);
  ASSERT_TRUE(p.usable);
  EXPECT_NEAR(pan_deg_of(p.pose), 5.0, 1e-9);
  EXPECT_NEAR(p.pose.translation_m.x(), 0.05, 1e-12);
  EXPECT_NEAR(p.pose.rotation.norm(), 1.0, 1e-12);
  // At a pose's own utime: that pose.
  EXPECT_NEAR(pan_deg_of(h.at("cam", kT0 + 66'000).pose), 6.6, 1e-9);
  // 40 ms beyond the newest (99 ms): extrapolated with the same motion.
  p = h.at("cam", kT0 + 139'000);
  ASSERT_TRUE(p.usable);
  EXPECT_NEAR(pan_deg_of(p.pose), 13.9, 1e-9);
  EXPECT_NEAR(p.pose.translation_m.x(), 0.139, 1e-12);
  // 41 ms beyond: unusable.
  p = h.at("cam", kT0 + 140'000);
  EXPECT_FALSE(p.usable);
  EXPECT_EQ(p.unusable_reason,
            "newest camera pose of moving camera 'cam' is 41.0 ms older than the frame (limit 40.0 ms)");
  // Before the oldest: held up to the limit.
  EXPECT_NEAR(pan_deg_of(h.at("cam", kT0 - 40'000).pose), 0.0, 1e-9);
  EXPECT_EQ(h.at("cam", kT0 - 41'000).unusable_reason,
            "frame is 41.0 ms older than the oldest camera pose kept of moving camera 'cam' (limit 40.0 ms)");
  // Another camera is not affected.
  EXPECT_FALSE(h.at("other", kT0).usable);
}

TEST(CameraPoseHistory, ACalibrationPublishedNowAndThenIsAStepNotAMotion) {
  CameraPoseHistory h(2'000'000, 40'000, 80'000);
  h.set_static("cam", panned(0));
  // 10 Hz: A, A, then the recalibrated B, B.
  ASSERT_TRUE(h.add("cam", kT0, panned(0, 0.1)));
  ASSERT_TRUE(h.add("cam", kT0 + 100'000, panned(0, 0.1)));
  ASSERT_TRUE(h.add("cam", kT0 + 200'000, panned(2, 0.3)));
  EXPECT_FALSE(h.moving("cam"));
  // B from its utime on, as long as it is the newest, however late the frame.
  for (int64_t t : {kT0 + 200'000, kT0 + 290'000, kT0 + 10'000'000}) {
    const PoseAtTime p = h.at("cam", t);
    ASSERT_TRUE(p.usable) << p.unusable_reason;
    EXPECT_DOUBLE_EQ(p.pose.translation_m.x(), 0.3);
  }
  // Before it, A (no blend across the step).
  EXPECT_DOUBLE_EQ(h.at("cam", kT0 + 150'000).pose.translation_m.x(), 0.1);
  ASSERT_TRUE(h.add("cam", kT0 + 300'000, panned(2, 0.3)));
  EXPECT_DOUBLE_EQ(h.at("cam", kT0 + 250'000).pose.translation_m.x(), 0.3);
}

TEST(CameraPoseHistory, KeepsOnlyTheHistorySpanAndStartsAnewInAnotherFrame) {
  CameraPoseHistory h(100'000, 10'000, 80'000);
  for (int i = 0; i <= 10; ++i) ASSERT_TRUE(h.add("cam", kT0 + i * 33'000, panned(i)));
  // Oldest kept: 330 - 100 = 230 ms -> the pose at 231 ms.
  EXPECT_TRUE(h.at("cam", kT0 + 231'000).usable);
  EXPECT_FALSE(h.at("cam", kT0 + 150'000).usable);
  // A pose in another frame: the old history is gone, a single pose is static.
  ASSERT_TRUE(h.add("cam", kT0 + 100'000, panned(0, 0, "base_link")));
  EXPECT_FALSE(h.moving("cam"));
  const PoseAtTime p = h.at("cam", kT0 + 5'000'000);
  ASSERT_TRUE(p.usable);
  EXPECT_EQ(p.pose.frame_id, "base_link");
}

}  // namespace
}  // namespace tofguard::robot_state
