// common/depth_frame.hpp: the one place depth frames are packed into and
// read from depth_image_t / link_labels_t.
#include "tofguard/common/depth_frame.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iomanip>
#include <limits>
#include <random>
#include <stdexcept>

#include "tofguard/common/wire_checks.hpp"

namespace tofguard {
namespace {

Intrinsics two_by_two() {
  Intrinsics in;
  in.width = 2;
  in.height = 2;
  in.fx = 100;
  in.fy = 101;
  in.cx = 0.5;
  in.cy = 0.6;
  return in;
}

TEST(DepthFrame, MillimetresRoundToNearestAndNeverInventDistances) {
  EXPECT_EQ(depth_mm_from_m(1.2346), 1235);  // nearest millimetre
  EXPECT_EQ(depth_mm_from_m(1.2344), 1234);
  EXPECT_EQ(depth_mm_from_m(0.0015), 2);  // halves round away from zero
  EXPECT_EQ(depth_mm_from_m(0.0004), 0);  // rounds to 0: no return
  EXPECT_EQ(depth_mm_from_m(0.0), 0);
  EXPECT_EQ(depth_mm_from_m(-1.0), 0);
  EXPECT_EQ(depth_mm_from_m(32.767), kMaxDepthMm);
  EXPECT_EQ(depth_mm_from_m(32.768), 0);  // beyond int16: invalid, not clipped
  EXPECT_EQ(depth_mm_from_m(40.0), 0);
  EXPECT_EQ(depth_mm_from_m(std::numeric_limits<double>::quiet_NaN()), 0);
  EXPECT_EQ(depth_mm_from_m(std::numeric_limits<double>::infinity()), 0);
  EXPECT_DOUBLE_EQ(metres_from_mm(1500), 1.5);
}

// depth_mm_from_m rounds without std::round's library call: the same result
// as std::round for every input, halves and the range's ends included.
TEST(DepthFrame, MillimetresAreStdRoundsToTheBit) {
  const auto reference = [](double depth_m) -> int16_t {
    const double mm = std::round(depth_m * 1000.0);
    return (mm > 0 && mm <= kMaxDepthMm) ? static_cast<int16_t>(mm) : int16_t{0};
  };
  std::vector<double> inputs = {0.0,
                                -0.0,
                                -0.0005,
                                0.0005,
                                0.00049999999999999,
                                std::nextafter(0.0005, 0.0),
                                std::nextafter(0.0005, 1.0),
                                32.7665,
                                std::nextafter(32.7665, 0.0),
                                std::nextafter(32.7665, 100.0),
                                32.767,
                                32.7675,
                                32.768,
                                1e300,
                                -1e300,
                                std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity(),
                                std::numeric_limits<double>::quiet_NaN(),
                                std::numeric_limits<double>::denorm_min()};
  // Every half millimetre and its neighbours, over the wire's range.
  for (int half = 0; half <= 2 * (kMaxDepthMm + 2); ++half) {
    const double m = half * 0.0005;
    inputs.push_back(m);
    inputs.push_back(std::nextafter(m, 0.0));
    inputs.push_back(std::nextafter(m, 100.0));
  }
  // And floats, as rendered depth comes: random depths to 40 m.
  std::mt19937 random(17);
  std::uniform_real_distribution<float> depth(-1.0f, 40.0f);
  for (int i = 0; i < 200000; ++i) inputs.push_back(static_cast<double>(depth(random)));
  for (const double m : inputs) ASSERT_EQ(depth_mm_from_m(m), reference(m)) << std::setprecision(17) << m;
  // A whole image (four pixels at a time, then the rest one by one) as
  // floats, which is what the renderer converts: every input that is a
  // float, then one fewer for a length not a multiple of 4.
  std::vector<float> image;
  for (const double m : inputs) {
    const auto f = static_cast<float>(m);
    if (static_cast<double>(f) == m || std::isnan(m)) image.push_back(f);
  }
  // Floats exactly half a millimetre from two: m / 16 for odd m (62.5 mm,
  // 187.5 mm, ...) to beyond the range, and their neighbours.
  for (int m = 1; m < 16 * 34; m += 2) {
    const float f = static_cast<float>(m) / 16.0f;
    image.insert(image.end(), {f, std::nextafter(f, 0.0f), std::nextafter(f, 100.0f)});
  }
  for (size_t length : {image.size(), image.size() - 1}) {
    const std::vector<float> part(image.begin(), image.begin() + static_cast<std::ptrdiff_t>(length));
    const std::vector<int16_t> mm = depth_mm_from_m(part);
    ASSERT_EQ(mm.size(), part.size());
    for (size_t i = 0; i < part.size(); ++i)
      ASSERT_EQ(mm[i], reference(static_cast<double>(part[i])))
          << std::setprecision(9) << part[i] << " at " << i;
  }
}

TEST(DepthFrame, MetresRoundTripThroughTheWireToTheMillimetre) {
  const std::vector<int16_t> mm = {1, 999, 1000, 1500, 32767, 0, -5};
  const std::vector<float> m = depth_m_from_mm(mm);
  EXPECT_EQ(m, (std::vector<float>{0.001f, 0.999f, 1.0f, 1.5f, 32.767f, 0.0f, 0.0f}));
  EXPECT_EQ(depth_mm_from_m(m), (std::vector<int16_t>{1, 999, 1000, 1500, 32767, 0, 0}));
  // Every value the wire can carry comes back unchanged, and its metres are
  // the correctly rounded float of mm / 1000.
  for (int d = 1; d <= kMaxDepthMm; ++d) {
    const float z = depth_m_from_mm({static_cast<int16_t>(d)})[0];
    ASSERT_EQ(z, static_cast<float>(d) / 1000.0f) << d;
    ASSERT_EQ(depth_mm_from_m(static_cast<double>(z)), d) << d;
  }
}

TEST(DepthFrame, MakeDepthImagePacksTheFrame) {
  const depth_image_t m = make_depth_image("cam", two_by_two(), 123, 7, true, {1.2345f, 0.0f, 40.0f, -1.0f},
                                           {10.4f, -3.0f, 1e6f, 5.0f});
  EXPECT_EQ(m.utime, 123);
  EXPECT_EQ(m.seq, 7);
  EXPECT_EQ(m.camera_id, "cam");
  EXPECT_TRUE(m.calibrated);
  EXPECT_EQ(m.width, 2);
  EXPECT_EQ(m.height, 2);
  EXPECT_EQ(m.fx, 100);
  EXPECT_EQ(m.fy, 101);
  EXPECT_EQ(m.cx, 0.5);
  EXPECT_EQ(m.cy, 0.6);
  EXPECT_EQ(m.num_pixels, 4);
  EXPECT_EQ(m.depth_mm, (std::vector<int16_t>{1235, 0, 0, 0}));  // 40 m: beyond int16 -> invalid
  EXPECT_EQ(m.num_amplitude, 4);
  EXPECT_EQ(m.amplitude, (std::vector<int16_t>{10, 0, 32767, 5}));
  EXPECT_EQ(check_depth_image(m), "");
  const depth_image_t no_amplitude = make_depth_image("cam", two_by_two(), 1, 0, false, {1, 1, 1, 1});
  EXPECT_EQ(no_amplitude.num_amplitude, 0);
  EXPECT_TRUE(no_amplitude.amplitude.empty());
  EXPECT_FALSE(no_amplitude.calibrated);
}

TEST(DepthFrame, MakeDepthImageRejectsBadSizes) {
  EXPECT_THROW(make_depth_image("cam", two_by_two(), 1, 0, false, {1}), std::invalid_argument);
  EXPECT_THROW(make_depth_image("cam", two_by_two(), 1, 0, false, {1, 1, 1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(make_depth_image("cam", two_by_two(), 1, 0, false, {1, 1, 1, 1}, {1, 2}),
               std::invalid_argument);
  Intrinsics negative = two_by_two();
  negative.width = -2;
  EXPECT_THROW(make_depth_image("cam", negative, 1, 0, false, {1, 1, 1, 1}), std::invalid_argument);
}

TEST(DepthFrame, IntrinsicsAndDepthComeBackFromTheMessage) {
  const depth_image_t m = make_depth_image("cam", two_by_two(), 1, 0, true, {0.5f, 1.0f, 0.0f, 2.25f});
  const Intrinsics in = intrinsics_of(m);
  EXPECT_EQ(in.width, 2);
  EXPECT_EQ(in.height, 2);
  EXPECT_EQ(in.fx, 100);
  EXPECT_EQ(in.fy, 101);
  EXPECT_EQ(in.cx, 0.5);
  EXPECT_EQ(in.cy, 0.6);
  EXPECT_EQ(depth_m_of(m), (std::vector<float>{0.5f, 1.0f, 0.0f, 2.25f}));
  // Round trip: packing with the decoded intrinsics gives the same message.
  const depth_image_t again = make_depth_image(m.camera_id, in, m.utime, m.seq, m.calibrated, depth_m_of(m));
  EXPECT_EQ(again.depth_mm, m.depth_mm);
  EXPECT_EQ(again.fx, m.fx);
  EXPECT_EQ(again.cy, m.cy);
}

TEST(DepthFrame, LabelValuesAreTheWireConstants) {
  EXPECT_EQ(kLabelNothing, 0);
  EXPECT_EQ(kLabelRobotFirst, 1);
  EXPECT_EQ(kLabelEnvironmentFirst, 1000);
  EXPECT_EQ(kLabelExtraObjectFirst, 2000);
  EXPECT_EQ(kMaxLabelledRobotLinks, 999);
  EXPECT_EQ(kMaxLabelledEnvironmentLinks, 1000);
}

TEST(DepthFrame, LabelsDecodeToLinkIndices) {
  // 3 robot links (0..2) and 2 environment links (3, 4).
  constexpr int kRobot = 3, kLinks = 5;
  EXPECT_EQ(link_of_label(0, kRobot, kLinks), -1);  // nothing
  EXPECT_EQ(link_of_label(1, kRobot, kLinks), 0);
  EXPECT_EQ(link_of_label(3, kRobot, kLinks), 2);
  EXPECT_EQ(link_of_label(4, kRobot, kLinks), -1);  // no 4th robot link
  EXPECT_EQ(link_of_label(1000, kRobot, kLinks), 3);
  EXPECT_EQ(link_of_label(1001, kRobot, kLinks), 4);
  EXPECT_EQ(link_of_label(1002, kRobot, kLinks), -1);  // no 3rd environment link
  EXPECT_EQ(link_of_label(2000, kRobot, kLinks), -1);  // an extra object
  EXPECT_EQ(link_of_label(-1, kRobot, kLinks), -1);
  EXPECT_EQ(link_of_label(500, kRobot, kLinks), -1);
  // Encoding is decoding's inverse for every link.
  for (int link = 0; link < kLinks; ++link) {
    EXPECT_EQ(link_of_label(label_of_link(link, kRobot), kRobot, kLinks), link) << link;
  }
  EXPECT_EQ(label_of_link(0, kRobot), 1);
  EXPECT_EQ(label_of_link(3, kRobot), 1000);
  EXPECT_EQ(label_of_link(0, 0), 1000);  // no robot links: the environment's first
  // Kinds, whatever the number of links.
  EXPECT_TRUE(is_robot_label(1));
  EXPECT_TRUE(is_robot_label(999));
  EXPECT_FALSE(is_robot_label(0));
  EXPECT_FALSE(is_robot_label(1000));
  EXPECT_TRUE(is_environment_label(1000));
  EXPECT_TRUE(is_environment_label(1999));
  EXPECT_FALSE(is_environment_label(2000));
  EXPECT_FALSE(is_environment_label(999));
}

TEST(DepthFrame, LinkLabelsRoundTrip) {
  const depth_image_t frame = make_depth_image("cam", two_by_two(), 55, 9, true, {1, 1, 1, 1});
  const std::vector<std::string> names = {"base", "link1", "floor"};
  const link_labels_t m = make_link_labels(frame, 2, names, {0, 1, 2, 1000});
  EXPECT_TRUE(m.usable);
  EXPECT_EQ(m.unusable_reason, "");
  EXPECT_EQ(m.utime, 55);
  EXPECT_EQ(m.seq, 9);
  EXPECT_EQ(m.camera_id, "cam");
  EXPECT_EQ(m.width, 2);
  EXPECT_EQ(m.height, 2);
  EXPECT_EQ(m.num_robot_links, 2);
  EXPECT_EQ(m.num_links, 3);
  EXPECT_EQ(m.link_name, names);
  EXPECT_EQ(m.num_pixels, 4);
  EXPECT_EQ(check_link_labels(m), "");
  std::vector<std::string> seen;
  for (int16_t label : m.label) {
    const int link = link_of_label(label, m.num_robot_links, m.num_links);
    seen.push_back(link < 0 ? "-" : m.link_name[link]);
  }
  EXPECT_EQ(seen, (std::vector<std::string>{"-", "base", "link1", "floor"}));

  const link_labels_t unusable = make_unusable_link_labels(frame, 2, names, "no joint state");
  EXPECT_FALSE(unusable.usable);
  EXPECT_EQ(unusable.unusable_reason, "no joint state");
  EXPECT_EQ(unusable.num_pixels, 0);
  EXPECT_TRUE(unusable.label.empty());
  EXPECT_EQ(unusable.num_links, 3);
  EXPECT_EQ(check_link_labels(unusable), "");
}

TEST(DepthFrame, LinkLabelsRejectBadSizes) {
  const depth_image_t frame = make_depth_image("cam", two_by_two(), 55, 9, true, {1, 1, 1, 1});
  EXPECT_THROW(make_link_labels(frame, 1, {"base"}, {0, 1, 1}), std::invalid_argument);
  EXPECT_THROW(make_link_labels(frame, 1, {"base"}, {0, 1, 1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(make_link_labels(frame, 2, {"base"}, {0, 1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(make_link_labels(frame, -1, {"base"}, {0, 1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(make_unusable_link_labels(frame, 2, {"base"}, "why"), std::invalid_argument);
}

}  // namespace
}  // namespace tofguard
