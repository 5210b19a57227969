// The camera geometry value types (tofguard/common/camera_geometry.hpp):
// what each accepts and refuses, the one-line reasons the config reader and
// the wire checks pass on, and TOFGUARD_DEMAND's abort with its line.
#include "tofguard/common/camera_geometry.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "tofguard/common/demand.hpp"

namespace tofguard {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The line a refused value gives, "" when accepted.
std::string why_intrinsics(int w, int h, double fx, double fy, double cx, double cy) {
  const auto v = Intrinsics::check(w, h, fx, fy, cx, cy);
  return v ? v->line() : "";
}

TEST(Intrinsics, AcceptsAPinholeCamera) {
  std::string why = "untouched";
  const auto k = Intrinsics::make(176, 144, 221.0, 220.5, 87.3, 71.8, &why);
  ASSERT_TRUE(k.has_value());
  EXPECT_EQ(why, "untouched");
  EXPECT_EQ(k->width, 176);
  EXPECT_EQ(k->height, 144);
  EXPECT_DOUBLE_EQ(k->fx, 221.0);
  EXPECT_DOUBLE_EQ(k->cy, 71.8);
  EXPECT_EQ(k->pixel_count(), 176u * 144u);
  EXPECT_FALSE(k->check());
  // The principal point may lie outside the image (a cropped sensor).
  EXPECT_EQ(why_intrinsics(1, 1, 1e-3, 1e-3, -50, 5000), "");
  EXPECT_EQ(why_intrinsics(kMaxImageSide, kMaxImageSide, 1, 1, 0, 0), "");
}

TEST(Intrinsics, RefusesEachBrokenFieldByName) {
  EXPECT_EQ(why_intrinsics(0, 144, 221, 220, 87, 71), "width: expected 1..8192, got 0");
  EXPECT_EQ(why_intrinsics(-4, 144, 221, 220, 87, 71), "width: expected 1..8192, got -4");
  EXPECT_EQ(why_intrinsics(176, 8193, 221, 220, 87, 71), "height: expected 1..8192, got 8193");
  EXPECT_EQ(why_intrinsics(176, 144, 0, 220, 87, 71), "fx: expected a focal length > 0 px, got 0");
  EXPECT_EQ(why_intrinsics(176, 144, -221, 220, 87, 71), "fx: expected a focal length > 0 px, got -221");
  EXPECT_EQ(why_intrinsics(176, 144, kNaN, 220, 87, 71), "fx: expected a focal length > 0 px, got nan");
  EXPECT_EQ(why_intrinsics(176, 144, 221, kInf, 87, 71), "fy: expected a focal length > 0 px, got inf");
  EXPECT_EQ(why_intrinsics(176, 144, 221, 220, kNaN, 71), "cx: expected a finite principal point, got nan");
  EXPECT_EQ(why_intrinsics(176, 144, 221, 220, 87, -kInf), "cy: expected a finite principal point, got -inf");

  std::string why;
  EXPECT_FALSE(Intrinsics::make(176, 144, 221, 0, 87, 71, &why).has_value());
  EXPECT_EQ(why, "fy: expected a focal length > 0 px, got 0");
  // Not set yet: refused, so a settings struct never filled is caught.
  EXPECT_EQ(Intrinsics().check()->field, "width");
}

TEST(UnitQuaternion, NormalisesWithinTheToleranceAndRefusesBeyond) {
  const Eigen::Quaterniond almost(1.0 + 5e-4, 0, 0, 0);
  std::string why;
  const auto q = UnitQuaternion::make(almost, kWireQuaternionTolerance, "rotation", &why);
  ASSERT_TRUE(q.has_value()) << why;
  EXPECT_NEAR(q->quaternion().norm(), 1.0, 1e-15);
  const Eigen::Quaterniond& as_eigen = *q;  // usable wherever a quaternion is
  EXPECT_NEAR(as_eigen.w(), 1.0, 1e-15);

  // The config's tolerance is tighter: the same value is a typo there.
  const auto refused = UnitQuaternion::check(almost, kConfigQuaternionTolerance, "rotation_wxyz");
  ASSERT_TRUE(refused.has_value());
  EXPECT_EQ(refused->field, "rotation_wxyz");
  EXPECT_EQ(refused->line(),
            "rotation_wxyz: expected a unit quaternion w, x, y, z (norm 1 within 1e-06), got norm 1.0005");

  EXPECT_FALSE(
      UnitQuaternion::make(Eigen::Quaterniond(2, 0, 0, 0), kWireQuaternionTolerance, "rotation", &why));
  EXPECT_EQ(why, "rotation: expected a unit quaternion w, x, y, z (norm 1 within 0.001), got norm 2");
  EXPECT_FALSE(
      UnitQuaternion::make(Eigen::Quaterniond(0, 0, 0, 0), kWireQuaternionTolerance, "rotation", &why));
  // A non-finite component is named by its index in w, x, y, z order.
  EXPECT_FALSE(
      UnitQuaternion::make(Eigen::Quaterniond(1, 0, kNaN, 0), kWireQuaternionTolerance, "rotation", &why));
  EXPECT_EQ(why, "rotation[2]: expected a finite number, got nan");

  EXPECT_TRUE(UnitQuaternion().quaternion().isApprox(Eigen::Quaterniond::Identity()));
}

TEST(CameraPose, ChecksFrameTranslationAndRotation) {
  const Eigen::Vector3d t(0.1, -0.2, 1.5);
  const Eigen::Quaterniond r(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
  std::string why;
  const auto pose = CameraPose::make("base_link", t, r, kWireQuaternionTolerance, &why);
  ASSERT_TRUE(pose.has_value()) << why;
  EXPECT_EQ(pose->frame_id, "base_link");
  EXPECT_TRUE(pose->translation_m.isApprox(t));
  EXPECT_TRUE(pose->rotation.isApprox(r));
  EXPECT_FALSE(pose->check());
  EXPECT_TRUE(pose->frame_from_optical().isApprox(Eigen::Translation3d(t) * r));

  const auto line = [](const std::string& frame, const Eigen::Vector3d& translation,
                       const Eigen::Quaterniond& q) {
    const auto v = CameraPose::check(frame, translation, q, kWireQuaternionTolerance);
    return v ? v->line() : "";
  };
  EXPECT_EQ(line("", t, r), "frame_id: expected a URDF link name, got an empty string");
  EXPECT_EQ(line("base_link", Eigen::Vector3d(0, kInf, 0), r),
            "translation[1]: expected a finite number of metres, got inf");
  EXPECT_EQ(line("base_link", t, Eigen::Quaterniond(0.5, 0, 0, 0)),
            "rotation: expected a unit quaternion w, x, y, z (norm 1 within 0.001), got norm 0.5");
  // Not set yet (no frame): refused.
  EXPECT_EQ(CameraPose().check()->field, "frame_id");
  // Accepted within the tolerance and stored normalised.
  const auto scaled = CameraPose::make("base_link", t, Eigen::Quaterniond(r.coeffs() * 1.0004),
                                       kWireQuaternionTolerance, &why);
  ASSERT_TRUE(scaled.has_value()) << why;
  EXPECT_NEAR(scaled->rotation.norm(), 1.0, 1e-15);
}

// The constructors are for values already checked: a bug that hands them a
// broken one must stop the process, with the file, line, condition and the
// reason on stderr.
TEST(CameraGeometryDeathTest, ConstructorsDemandTheirInvariants) {
  EXPECT_DEATH(
      Intrinsics(176, 144, -1.0, 220.0, 87.0, 71.0),
      "tofguard: internal invariant failed: .*camera_geometry.cpp:[0-9]+: !v: intrinsics: fx: expected a "
      "focal length > 0 px, got -1");
  EXPECT_DEATH(UnitQuaternion(Eigen::Quaterniond(2, 0, 0, 0)),
               "quaternion: expected a unit quaternion w, x, y, z \\(norm 1 within 0.001\\), got norm 2");
  EXPECT_DEATH(CameraPose("", Eigen::Vector3d::Zero(), UnitQuaternion()),
               "camera pose: frame_id: expected a URDF link name");
  EXPECT_DEATH(CameraPose("base_link", Eigen::Vector3d(kNaN, 0, 0), UnitQuaternion()), "translation\\[0\\]");
}

TEST(DemandDeathTest, AbortsWithFileLineConditionAndMessage) {
  const int pixels = 12;
  const int expected_pixels = 3 * 5;
  EXPECT_DEATH(
      TOFGUARD_DEMAND(pixels == expected_pixels, "depth has " + std::to_string(pixels) + " pixels"),
      "tofguard: internal invariant failed: .*camera_geometry_test.cpp:[0-9]+: pixels == expected_pixels: "
      "depth has 12 pixels");
  // Always on: the condition is evaluated in every build type, and the
  // message only when it fails.
  int evaluated = 0;
  int messages = 0;
  const auto message = [&] {
    ++messages;
    return std::string("unused");
  };
  TOFGUARD_DEMAND(++evaluated == 1, message());
  EXPECT_EQ(evaluated, 1);
  EXPECT_EQ(messages, 0);
}

}  // namespace
}  // namespace tofguard
