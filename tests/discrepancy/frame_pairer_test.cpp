// Pairing camera, rendered and label frames by seq with a bounded wait.
#include <gtest/gtest.h>

#include "synthetic_frames.hpp"
#include "tofguard/discrepancy/frame_pairer.hpp"

namespace tofguard::test {
namespace {

using discrepancy::CameraFrame;
using discrepancy::FramePairer;
using discrepancy::PairingOutput;

constexpr int64_t kTimeoutUs = 100'000;

CameraFrame camera(int64_t seq) { return CameraFrame{depth_frame({1, 2}, seq, 2, 1), 0, 0}; }
depth_image_t rendered(int64_t seq) { return depth_frame({1, 2}, seq, 2, 1); }
link_labels_t labels(int64_t seq) { return labels_frame({0, 0}, seq, 2, 1); }

TEST(FramePairer, PairsBySeqWhateverTheOrder) {
  FramePairer pairer(kTimeoutUs, 8);
  PairingOutput out;
  pairer.add_labels(labels(2), 0, &out);
  pairer.add_camera(camera(1), 10, &out);
  pairer.add_camera(camera(2), 20, &out);
  pairer.add_rendered(rendered(1), 30, &out);
  EXPECT_TRUE(out.paired.empty());
  pairer.add_rendered(rendered(2), 40, &out);
  ASSERT_EQ(out.paired.size(), 1u);
  EXPECT_EQ(out.paired[0].camera.image.seq, 2);
  EXPECT_EQ(out.paired[0].rendered->seq, 2);
  EXPECT_EQ(out.paired[0].labels.seq, 2);
  pairer.add_labels(labels(1), 50, &out);
  ASSERT_EQ(out.paired.size(), 2u);
  EXPECT_EQ(out.paired[1].camera.image.seq, 1);
  EXPECT_EQ(pairer.pending(), 0u);
  EXPECT_TRUE(out.unpaired.empty());
  EXPECT_EQ(out.dropped_partners, 0);
}

TEST(FramePairer, UnusableLabelsNeedNoRenderedFrame) {
  FramePairer pairer(kTimeoutUs, 8);
  PairingOutput out;
  pairer.add_camera(camera(5), 0, &out);
  pairer.add_labels(unusable_labels(5, "joint state too old"), 10, &out);
  ASSERT_EQ(out.paired.size(), 1u);
  EXPECT_FALSE(out.paired[0].rendered.has_value());
  // A rendered frame that still comes for the finished seq is dropped.
  pairer.add_rendered(rendered(5), 20, &out);
  EXPECT_EQ(out.dropped_partners, 1);
  EXPECT_EQ(pairer.pending(), 0u);
}

TEST(FramePairer, CameraFrameWithoutRenderingIsHandedBackAfterTheTimeout) {
  FramePairer pairer(kTimeoutUs, 8);
  PairingOutput out;
  pairer.add_camera(camera(3), 1'000, &out);
  pairer.add_labels(labels(3), 2'000, &out);
  pairer.expire(1'000 + kTimeoutUs, &out);  // exactly at the deadline: still waits
  EXPECT_TRUE(out.unpaired.empty());
  pairer.expire(1'001 + kTimeoutUs, &out);
  ASSERT_EQ(out.unpaired.size(), 1u);
  EXPECT_EQ(out.unpaired[0].camera.image.seq, 3);
  EXPECT_EQ(out.unpaired[0].reason, "no rendered frame for seq 3: waited 100 ms");
  // The late rendered frame is dropped, not paired.
  pairer.add_rendered(rendered(3), 200'000, &out);
  EXPECT_TRUE(out.paired.empty());
  EXPECT_EQ(out.dropped_partners, 1);
}

TEST(FramePairer, PartnersWithoutCameraFrameAreDroppedAfterTheTimeout) {
  FramePairer pairer(kTimeoutUs, 8);
  PairingOutput out;
  pairer.add_rendered(rendered(8), 0, &out);
  pairer.add_labels(labels(8), 0, &out);
  pairer.expire(kTimeoutUs + 1, &out);
  EXPECT_EQ(out.dropped_partners, 2);
  EXPECT_TRUE(out.unpaired.empty());
  EXPECT_EQ(pairer.pending(), 0u);
}

TEST(FramePairer, AtMostMaxPendingWaitOldestPushedOutFirst) {
  FramePairer pairer(kTimeoutUs, 3);
  PairingOutput out;
  for (int64_t seq = 10; seq < 15; ++seq) pairer.add_camera(camera(seq), seq, &out);
  EXPECT_EQ(pairer.pending(), 3u);
  ASSERT_EQ(out.unpaired.size(), 2u);
  EXPECT_EQ(out.unpaired[0].camera.image.seq, 10);
  EXPECT_EQ(out.unpaired[1].camera.image.seq, 11);
  EXPECT_NE(out.unpaired[0].reason.find("pushed out"), std::string::npos);
}

TEST(FramePairer, RepeatedCameraSeqIsNeverJudgedTwice) {
  FramePairer pairer(kTimeoutUs, 8);
  PairingOutput out;
  pairer.add_camera(camera(4), 0, &out);
  pairer.add_camera(camera(4), 1, &out);
  ASSERT_EQ(out.unpaired.size(), 1u);
  EXPECT_EQ(out.unpaired[0].reason, "seq 4 already seen");
}

}  // namespace
}  // namespace tofguard::test
