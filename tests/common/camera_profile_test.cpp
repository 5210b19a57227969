// A commissioned camera's profile (common/camera_profile.hpp): the
// correction it applies (by radial distance and per pixel), the check that
// a frame is its camera's, and its file's round trip and errors.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tofguard/common/camera_profile.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tool_support.hpp"

namespace tofguard {
namespace {

Intrinsics small_camera() {
  Intrinsics in;
  in.width = 8;
  in.height = 6;
  in.fx = 5;
  in.fy = 5;
  in.cx = 3.5;
  in.cy = 2.5;
  return in;
}

// A profile of small_camera(): +10 mm at 1.0 m and +30 mm at 2.0 m (bins of
// 0.5 m: 10, 20, 30), pixel i offset by i / 10 mm.
CameraProfile profile_of(const Intrinsics& in) {
  CameraProfile p;
  p.camera_id = "cam";
  p.width = in.width;
  p.height = in.height;
  p.fx = in.fx;
  p.fy = in.fy;
  p.cx = in.cx;
  p.cy = in.cy;
  p.distance_first_m = 1.0;
  p.distance_bin_m = 0.5;
  p.distance_correction_mm = {10, 20, 30};
  p.measured_on = "a test";
  for (int i = 0; i < in.width * in.height; ++i) p.pixel_correction_mm.push_back(static_cast<float>(i) / 10);
  return p;
}

// Labels of small_camera()'s 48 pixels, all the scene's: robot link 0 a
// base no joint moves, link 1 moved by axis 0, then one environment link.
link_labels_t base_and_moving_link_labels() {
  link_labels_t labels;
  labels.num_robot_links = 2;
  labels.num_links = 3;
  labels.num_pixels = 48;
  labels.label.assign(48, kLabelEnvironmentFirst);
  labels.link_axis = {-1, 0};
  labels.num_link_axes = 2;
  return labels;
}

TEST(CameraProfile, InterpolatesByRadialDistanceAndHoldsTheEnds) {
  const CameraProfile p = profile_of(small_camera());
  EXPECT_DOUBLE_EQ(p.distance_correction_at(0.2), 10);
  EXPECT_DOUBLE_EQ(p.distance_correction_at(1.25), 15);
  EXPECT_DOUBLE_EQ(p.distance_correction_at(2.0), 30);
  EXPECT_DOUBLE_EQ(p.distance_correction_at(9.0), 30);
}

// Z' = Z + f c(Z / f) + offset, f = Z / r of the pixel's ray.
TEST(CameraProfile, CorrectsEachPixelAlongItsRay) {
  const Intrinsics in = small_camera();
  const CameraProfile p = profile_of(in);
  depth_image_t frame = make_depth_image("cam", in, 1, 1, true, std::vector<float>(48, 1.5f));
  frame.depth_mm[5] = 0;  // invalid stays invalid
  apply_camera_profile(p, &frame);
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      const int i = v * in.width + u;
      if (i == 5) {
        EXPECT_EQ(frame.depth_mm[5], 0);
        continue;
      }
      const double x = (u - in.cx) / in.fx, y = (v - in.cy) / in.fy;
      const double f = 1 / std::sqrt(1 + x * x + y * y);
      const double expected = 1500 + f * p.distance_correction_at(1.5 / f) + i / 10.0;
      EXPECT_NEAR(frame.depth_mm[static_cast<size_t>(i)], expected, 0.5) << "pixel " << u << ", " << v;
    }
  }
}

// The map learned on the static scene is smooth over the image (here the
// ramp i / 10) where the scene's surfaces add to it; the sensor's fixed
// pattern is what stands out of its 5x5 neighbours (here +5 mm at (3, 2)).
// A moving link's pixels get only that; the scene's and the robot's base's
// the whole map.
TEST(CameraProfile, AMovingLinksPixelGetsTheFixedPatternAndTheSceneTheWholeMap) {
  const Intrinsics in = small_camera();
  CameraProfile p = profile_of(in);
  const size_t spike = 2 * 8 + 3, beside = spike + 1;
  p.pixel_correction_mm[spike] += 5.0f;
  derive_fixed_pattern(&p);
  // The ramp's median within the window is the next value above the spike's.
  EXPECT_NEAR(p.fixed_pattern_mm[spike], 6.9 - 2.0, 1e-4);
  EXPECT_NEAR(p.fixed_pattern_mm[beside], 2.0 - 2.1, 1e-4);
  EXPECT_EQ(p.fixed_pattern_mm[0], 0.0f) << "pixel 0 is unmapped (0)";

  link_labels_t labels = base_and_moving_link_labels();
  labels.label[spike] = kLabelRobotFirst + 1;
  labels.label[beside] = kLabelRobotFirst + 0;
  const depth_image_t measured = make_depth_image("cam", in, 1, 1, true, std::vector<float>(48, 1.5f));
  depth_image_t by_label = measured, whole = measured, derived_here = measured;
  apply_camera_profile(p, &by_label, &labels);
  apply_camera_profile(p, &whole);
  CameraProfile not_derived = p;
  not_derived.fixed_pattern_mm.clear();
  apply_camera_profile(not_derived, &derived_here, &labels);
  EXPECT_EQ(by_label.depth_mm[spike] - whole.depth_mm[spike], -2) << "6.9 mm of map, 4.9 of fixed pattern";
  EXPECT_EQ(by_label.depth_mm[beside], whole.depth_mm[beside]) << "the base keeps the whole map";
  EXPECT_EQ(by_label.depth_mm[beside + 1], whole.depth_mm[beside + 1]) << "the scene keeps the whole map";
  EXPECT_EQ(derived_here.depth_mm, by_label.depth_mm);
}

// The profile's range: bin centres 1.0-2.0 m, a bin (0.5 m) of margin
// either side. Counted by the rendered (model's) distance, on the moving
// links' pixels only.
TEST(CameraProfile, CoverageCountsTheMovingLinksRenderedPixelsBeyondTheRange) {
  const Intrinsics in = small_camera();
  const CameraProfile p = profile_of(in);
  link_labels_t labels = base_and_moving_link_labels();
  std::vector<float> rendered_m(48, 3.0f);  // the scene beyond the range: not the arm
  // Pixels 0..3: the moving link at Z 0.30 m, radial 0.30-0.40 m (f >=
  // 0.75 on row 0): below 1.0 - 0.5 m, outside.
  for (int i = 0; i < 4; ++i) {
    labels.label[static_cast<size_t>(i)] = kLabelRobotFirst + 1;
    rendered_m[static_cast<size_t>(i)] = 0.30f;
  }
  // Pixels 4..7: the moving link at Z 1.2 m, inside; 8..11: the base at
  // 0.3 m, not counted (no joint moves it).
  for (int i = 4; i < 8; ++i) {
    labels.label[static_cast<size_t>(i)] = kLabelRobotFirst + 1;
    rendered_m[static_cast<size_t>(i)] = 1.2f;
  }
  for (int i = 8; i < 12; ++i) {
    labels.label[static_cast<size_t>(i)] = kLabelRobotFirst + 0;
    rendered_m[static_cast<size_t>(i)] = 0.3f;
  }
  const depth_image_t rendered = make_depth_image("cam", in, 1, 1, true, rendered_m);
  ProfileCoverage coverage;
  add_profile_coverage(p, rendered, labels, {}, &coverage);
  EXPECT_EQ(coverage.pixels, 8);
  EXPECT_EQ(coverage.outside, 4);
  EXPECT_DOUBLE_EQ(coverage.first_m, 1.0);
  EXPECT_DOUBLE_EQ(coverage.last_m, 2.0);
  EXPECT_GE(coverage.nearest_m, 0.30);
  EXPECT_LT(coverage.farthest_m, 0.41);
  // Only the pixels `used` marks.
  std::vector<uint8_t> used(48, 1);
  used[0] = used[4] = 0;
  ProfileCoverage of_used;
  add_profile_coverage(p, rendered, labels, used, &of_used);
  EXPECT_EQ(of_used.pixels, 6);
  EXPECT_EQ(of_used.outside, 3);
}

TEST(CameraProfile, NamesWhatDiffersFromTheFramesCamera) {
  const Intrinsics in = small_camera();
  const CameraProfile p = profile_of(in);
  depth_image_t frame = make_depth_image("cam", in, 1, 1, true, std::vector<float>(48, 1.5f));
  EXPECT_EQ(profile_mismatch(p, frame), "");
  depth_image_t other = frame;
  other.camera_id = "other";
  EXPECT_NE(profile_mismatch(p, other).find("camera_id 'cam', the frame is from 'other'"), std::string::npos);
  other = frame;
  other.fx += 0.01;
  EXPECT_NE(profile_mismatch(p, other).find("fx 5, the frame has 5.01"), std::string::npos)
      << profile_mismatch(p, other);
  Intrinsics larger = in;
  larger.width = 16;
  const depth_image_t wide = make_depth_image("cam", larger, 1, 1, true, std::vector<float>(96, 1.5f));
  EXPECT_NE(profile_mismatch(p, wide).find("made for 8x6, the frame is 16x6"), std::string::npos);
}

TEST(CameraProfile, TheFileHoldsWhatWasWritten) {
  const CameraProfile p = profile_of(small_camera());
  const std::string path = test::output_dir() + "/camera-profile-roundtrip.yaml";
  test::write_file(path, camera_profile_yaml(p));
  const CameraProfile read = read_camera_profile(path);
  EXPECT_EQ(read.camera_id, "cam");
  EXPECT_EQ(read.width, 8);
  EXPECT_DOUBLE_EQ(read.cx, 3.5);
  EXPECT_EQ(read.distance_correction_mm, p.distance_correction_mm);
  ASSERT_EQ(read.pixel_correction_mm.size(), 48u);
  EXPECT_NEAR(read.pixel_correction_mm[47], 4.7, 1e-4);
  EXPECT_EQ(read.measured_on, "a test");
}

TEST(CameraProfile, AFileWithTooFewPixelsIsRefusedNamingTheKey) {
  const CameraProfile p = profile_of(small_camera());
  std::string text = camera_profile_yaml(p);
  text.replace(text.find("width: 8"), 8, "width: 9");
  const std::string path = test::output_dir() + "/camera-profile-short.yaml";
  test::write_file(path, text);
  try {
    read_camera_profile(path);
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("pixel_correction_mm: expected a list of 54 numbers, got 48 entries"),
              std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace tofguard
