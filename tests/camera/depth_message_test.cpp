#include "tofguard/camera/depth_message.hpp"

#include <gtest/gtest.h>

namespace tofguard::camera {
namespace {

TEST(DepthMessage, RoundsToMillimetresAndNeverInventsDistances) {
  CameraSettings c;
  c.id = "cam";
  c.intrinsics.width = 2;
  c.intrinsics.height = 2;
  c.intrinsics.fx = 100;
  c.intrinsics.fy = 101;
  c.intrinsics.cx = 0.5;
  c.intrinsics.cy = 0.6;
  const depth_image_t m =
      make_depth_image(c, 123, 7, true, {1.2345f, 0.0f, 40.0f, -1.0f}, {10.4f, -3.0f, 1e6f, 5.0f});
  EXPECT_EQ(m.utime, 123);
  EXPECT_EQ(m.seq, 7);
  EXPECT_EQ(m.camera_id, "cam");
  EXPECT_TRUE(m.calibrated);
  EXPECT_EQ(m.fy, 101);
  EXPECT_EQ(m.num_pixels, 4);
  EXPECT_EQ(m.depth_mm, (std::vector<int16_t>{1235, 0, 0, 0}));  // 40 m: beyond int16 -> invalid
  EXPECT_EQ(m.num_amplitude, 4);
  EXPECT_EQ(m.amplitude, (std::vector<int16_t>{10, 0, 32767, 5}));
  EXPECT_EQ(make_depth_image(c, 0, 0, false, {1, 1, 1, 1}, {}).num_amplitude, 0);
  EXPECT_THROW(make_depth_image(c, 0, 0, false, {1}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace tofguard::camera
