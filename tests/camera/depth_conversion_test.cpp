#include "tofguard/camera/depth_conversion.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace tofguard::camera {
namespace {

TEST(Raw16ToDistance, AppliesTheDepthUnitLittleEndian) {
  // 10000 = 0x2710 -> 1250 mm at 0.125 mm/count; 0 stays invalid; 0xffff.
  const std::vector<uint8_t> bytes = {0x10, 0x27, 0x00, 0x00, 0xff, 0xff};
  const auto d = raw16_to_distance_m(bytes.data(), 3, 0.125);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_FLOAT_EQ(d[0], 1.25f);
  EXPECT_EQ(d[1], 0.0f);
  EXPECT_FLOAT_EQ(d[2], 65535 * 0.125e-3f);
  const auto mm = raw16_to_distance_m(bytes.data(), 1, 1.0);
  EXPECT_FLOAT_EQ(mm[0], 10.0f);
}

TEST(Raw16ToDistance, FormatNames) {
  EXPECT_EQ(parse_raw_depth_format("z16"), RawDepthFormat::kZ16);
  EXPECT_EQ(parse_raw_depth_format("gray16"), RawDepthFormat::kGray16);
  EXPECT_STREQ(fourcc(RawDepthFormat::kZ16), "Z16 ");
  EXPECT_STREQ(fourcc(RawDepthFormat::kGray16), "Y16 ");
  EXPECT_THROW(parse_raw_depth_format("yuyv"), std::invalid_argument);
}

TEST(RadialToZ, RecoversZOfKnownPoints) {
  Intrinsics in;
  in.width = 80;
  in.height = 60;
  in.fx = 100;
  in.fy = 50;
  in.cx = 10;
  in.cy = 20;
  const RadialToZ to_z(in);
  // A point at (0.6, 0.8, 2.0) m lands on u = 100 * 0.3 + 10 = 40,
  // v = 50 * 0.4 + 20 = 40; its radial distance is |p|.
  std::vector<float> d(80 * 60, 0.0f);
  const double r = std::sqrt(0.6 * 0.6 + 0.8 * 0.8 + 2.0 * 2.0);
  d[40 * 80 + 40] = static_cast<float>(r);
  d[20 * 80 + 10] = 3.0f;  // on the optical axis Z = r
  to_z.apply(&d);
  EXPECT_NEAR(d[40 * 80 + 40], 2.0, 1e-6);
  EXPECT_NEAR(d[20 * 80 + 10], 3.0, 1e-6);
  EXPECT_EQ(d[0], 0.0f);  // invalid stays invalid
  std::vector<float> wrong(5);
  EXPECT_THROW(to_z.apply(&wrong), std::invalid_argument);
}

}  // namespace
}  // namespace tofguard::camera
