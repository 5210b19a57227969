// discrepancy/witness_frames.hpp: the other cameras' frames paired with
// their labels by seq, handed out for a judged frame within two of their
// frame periods, each with its offset; a frame its camera's profile does
// not fit is refused with the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "tofguard/common/camera_profile.hpp"
#include "tofguard/discrepancy/witness_frames.hpp"

namespace tofguard::discrepancy {
namespace {

constexpr int64_t kStartUs = 1'700'000'000'000'000;
constexpr int64_t kPeriodUs = 33'333;  // 30 Hz

depth_image_t side_frame(int64_t seq) {
  depth_image_t d{};
  d.utime = kStartUs + seq * kPeriodUs;
  d.seq = seq;
  d.camera_id = "tof-side";
  d.width = 4;
  d.height = 3;
  d.num_pixels = 12;
  d.fx = d.fy = 5;
  d.cx = 1.5;
  d.cy = 1;
  d.depth_mm.assign(12, 1500);
  return d;
}

// Its labels, usable, with the camera 2 m up its mast (identity rotation).
link_labels_t side_labels(int64_t seq, bool with_pose = true) {
  link_labels_t l{};
  l.utime = kStartUs + seq * kPeriodUs;
  l.seq = seq;
  l.camera_id = "tof-side";
  l.usable = true;
  l.width = 4;
  l.height = 3;
  l.num_pixels = 12;
  l.label.assign(12, 0);
  l.optical_pose_given = with_pose;
  const double pose[12] = {1, 0, 0, -0.1, 0, 1, 0, 0.7, 0, 0, 1, 2.0};
  std::copy(pose, pose + 12, l.world_from_optical);
  return l;
}

settings::WitnessCameraSettings side_camera() {
  settings::WitnessCameraSettings c;
  c.id = "tof-side";
  c.depth_channel = "TOF_DEPTH/tof-side";
  c.labels_channel = "TOF_LABELS/tof-side";
  c.rate_hz = 30;
  return c;
}

TEST(WitnessFrames, AFrameIsLookedThroughOnceItsLabelsCame) {
  WitnessFrames frames({side_camera()});
  frames.add_depth(0, side_frame(10));
  EXPECT_TRUE(frames.views_at(kStartUs + 10 * kPeriodUs).empty()) << "no labels yet: no pose";
  EXPECT_EQ(frames.add_labels(0, side_labels(10)), "");
  const std::vector<WitnessView> views = frames.views_at(kStartUs + 10 * kPeriodUs + 5'000);
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0].camera_id, "tof-side");
  EXPECT_EQ(views[0].offset_us, -5'000);
  EXPECT_NEAR((views[0].optical_from_world * Eigen::Vector3d(-0.1, 0.7, 2.0)).norm(), 0.0, 1e-12);
  // Labels without the camera's pose, or of a frame not kept: nothing.
  frames.add_depth(0, side_frame(11));
  EXPECT_EQ(frames.add_labels(0, side_labels(11, /*with_pose=*/false)), "");
  EXPECT_EQ(frames.add_labels(0, side_labels(12)), "");
  EXPECT_EQ(frames.views_at(kStartUs + 11 * kPeriodUs)[0].depth.seq, 10);
}

TEST(WitnessFrames, TheNearestFrameWithinTwoPeriodsElseNone) {
  WitnessFrames frames({side_camera()});
  for (int64_t seq = 10; seq < 13; ++seq) {
    frames.add_depth(0, side_frame(seq));
    frames.add_labels(0, side_labels(seq));
  }
  EXPECT_EQ(frames.views_at(kStartUs + 11 * kPeriodUs + 10'000)[0].depth.seq, 11);
  // The newest is 12: a judged frame 2 periods after it still gets it, 3 do not.
  EXPECT_EQ(frames.views_at(kStartUs + 14 * kPeriodUs)[0].depth.seq, 12);
  EXPECT_TRUE(frames.views_at(kStartUs + 15 * kPeriodUs).empty());
}

TEST(WitnessFrames, AFrameItsProfileDoesNotFitIsRefusedWithTheReason) {
  settings::WitnessCameraSettings camera = side_camera();
  auto profile = std::make_shared<CameraProfile>();
  profile->camera_id = "tof-mast";  // another camera's
  camera.profile = profile;
  WitnessFrames frames({camera});
  frames.add_depth(0, side_frame(10));
  const std::string why = frames.add_labels(0, side_labels(10));
  EXPECT_NE(why.find("tof-mast"), std::string::npos) << why;
  EXPECT_TRUE(frames.views_at(kStartUs + 10 * kPeriodUs).empty());
}

}  // namespace
}  // namespace tofguard::discrepancy
