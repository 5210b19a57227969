// tofguard-discrepancy as a real process over real LCM (private network
// namespace): frames paired by seq, unpaired camera frames published as
// unusable, malformed input on every channel dropped and counted while good
// frames are still compared.
#include <gtest/gtest.h>

#include "chain_bus.hpp"
#include "synthetic_frames.hpp"
#include "tofguard/joint_state_t.hpp"

namespace tofguard::test {
namespace {

const auto kDeadline = std::chrono::seconds(10);

class DiscrepancyProcess : public ::testing::Test {
 protected:
  void SetUp() override {
    process_ = std::make_unique<Subprocess>(
        "discrepancy-process", std::vector<std::string>{bin_dir() + "/tofguard-discrepancy", "--config",
                                                        ideal_camera_config("discrepancy")});
    // Up when its heartbeat comes.
    ASSERT_TRUE(wait_until([&] { return !bus_.last_heartbeat("tofguard-discrepancy").process.empty(); },
                           kDeadline, [&] { bus_.poll(); }))
        << process_->stderr_text();
  }
  void TearDown() override {
    process_->signal(SIGTERM);
    EXPECT_EQ(process_->wait(std::chrono::seconds(5)), 0) << process_->stderr_text();
  }

  // Publishes camera, rendered and labels of one seq (camera seen with
  // link2 shifted by `shift_px`).
  void publish_frame(int64_t seq, int shift_px = 0, bool with_rendering = true) {
    const SyntheticImage model = draw(default_arm());
    const depth_image_t camera = depth_frame(with_noise(draw(default_arm(shift_px)).depth_mm, seq), seq);
    bus_.images.publish("TOF_DEPTH", &camera);
    if (!with_rendering) return;
    const depth_image_t rendered = depth_frame(model.depth_mm, seq);
    const link_labels_t labels = labels_frame(model.label, seq);
    bus_.images.publish("TOF_RENDERED", &rendered);
    bus_.images.publish("TOF_LABELS", &labels);
  }

  const discrepancy_t* find(int64_t seq) const {
    for (const auto& d : bus_.discrepancies.messages) {
      if (d.seq == seq) return &d;
    }
    return nullptr;
  }

  bool wait_for(int64_t seq) {
    return wait_until([&] { return find(seq) != nullptr; }, kDeadline, [&] { bus_.poll(); });
  }

  ChainBus bus_;
  std::unique_ptr<Subprocess> process_;
};

TEST_F(DiscrepancyProcess, PairedFramesAreComparedAndKeepTheirUtimeAndSeq) {
  publish_frame(1);
  publish_frame(2, /*shift_px=*/16);
  ASSERT_TRUE(wait_for(1));
  ASSERT_TRUE(wait_for(2));
  const discrepancy_t& good = *find(1);
  EXPECT_TRUE(good.usable) << good.unusable_reason;
  EXPECT_EQ(good.utime, depth_frame({}, 1).utime);
  EXPECT_EQ(good.num_match, kWidth * kHeight);
  EXPECT_EQ(good.link_name, (std::vector<std::string>{"base_link", "link1", "link2", "floor"}));
  EXPECT_NE(good.depth_hash, 0);
  const discrepancy_t& shifted = *find(2);
  EXPECT_EQ(shifted.num_robot_missing, 320);
  // Per link, the silhouette rows (link2's top and bottom row border the
  // floor) are left out: 16 columns x 18 rows.
  EXPECT_EQ(shifted.link_farther[2], 16 * 18);
  EXPECT_EQ(shifted.num_unexpected_surface, 320);
}

TEST_F(DiscrepancyProcess, CameraFrameWithoutRenderingIsPublishedUnusableAndCountedDropped) {
  const int64_t sent_us = monotonic_us();
  publish_frame(10, 0, /*with_rendering=*/false);
  ASSERT_TRUE(wait_for(10));
  const int64_t waited_us = bus_.discrepancies.arrival_us.back() - sent_us;
  const discrepancy_t& d = *find(10);
  EXPECT_FALSE(d.usable);
  EXPECT_EQ(d.unusable_kind, discrepancy_t::UNUSABLE_NO_RENDERING);
  EXPECT_EQ(d.unusable_reason, "no rendered frame and labels for seq 10: waited 100 ms");
  // Not before the pairing deadline.
  EXPECT_GE(waited_us, 100'000);
  ASSERT_TRUE(wait_until([&] { return bus_.last_heartbeat("tofguard-discrepancy").frames_dropped >= 1; },
                         kDeadline, [&] { bus_.poll(); }));
}

TEST_F(DiscrepancyProcess, UnusableLabelsGiveAnUnusableFrameAtOnce) {
  const depth_image_t camera = depth_frame(draw(default_arm()).depth_mm, 20);
  const link_labels_t labels = unusable_labels(20, "joint 'a4' missing from the joint state");
  bus_.images.publish("TOF_DEPTH", &camera);
  bus_.images.publish("TOF_LABELS", &labels);
  ASSERT_TRUE(wait_for(20));
  EXPECT_FALSE(find(20)->usable);
  EXPECT_EQ(find(20)->unusable_kind, discrepancy_t::UNUSABLE_RENDERER);
  EXPECT_EQ(find(20)->unusable_reason, "renderer: joint 'a4' missing from the joint state");
}

TEST_F(DiscrepancyProcess, MalformedInputOnEveryChannelIsDroppedAndCounted) {
  const SyntheticImage model = draw(default_arm());
  // TOF_DEPTH: num_pixels != width*height, another camera (validation
  // errors), another type (decode error).
  depth_image_t wrong_size = depth_frame(model.depth_mm, 30);
  wrong_size.num_pixels = 5;
  wrong_size.depth_mm.resize(5);
  bus_.images.publish("TOF_DEPTH", &wrong_size);
  depth_image_t other_camera = depth_frame(model.depth_mm, 30);
  other_camera.camera_id = "someone-else";
  bus_.images.publish("TOF_DEPTH", &other_camera);
  joint_state_t not_an_image{};
  bus_.images.publish("TOF_DEPTH", &not_an_image);
  // TOF_RENDERED: negative size (validation), truncated (decode).
  depth_image_t negative = depth_frame({}, 30, 0, 0);
  negative.width = -4;
  bus_.images.publish("TOF_RENDERED", &negative);
  const depth_image_t good_rendered = depth_frame(model.depth_mm, 30);
  std::vector<uint8_t> bytes(good_rendered.getEncodedSize());
  good_rendered.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  bus_.images.publish("TOF_RENDERED", bytes.data(), static_cast<unsigned>(bytes.size() / 3));
  // TOF_LABELS: huge size (validation), another type (decode).
  link_labels_t huge = labels_frame({}, 30);
  huge.width = 100000;
  huge.height = 100000;
  huge.num_pixels = 0;
  bus_.images.publish("TOF_LABELS", &huge);
  bus_.images.publish("TOF_LABELS", &good_rendered);

  // The good frame after all that is still compared.
  publish_frame(31);
  ASSERT_TRUE(wait_for(31));
  EXPECT_TRUE(find(31)->usable);
  EXPECT_EQ(find(30), nullptr);
  ASSERT_TRUE(wait_until(
      [&] {
        const heartbeat_t hb = bus_.last_heartbeat("tofguard-discrepancy");
        return hb.decode_errors == 3 && hb.validation_errors == 4 && hb.frames_out >= 1;
      },
      kDeadline, [&] { bus_.poll(); }))
      << "decode " << bus_.last_heartbeat("tofguard-discrepancy").decode_errors << " validation "
      << bus_.last_heartbeat("tofguard-discrepancy").validation_errors;
  EXPECT_TRUE(process_->running());
  EXPECT_NE(process_->stderr_text().find("TOF_DEPTH: num_pixels"), std::string::npos)
      << process_->stderr_text();
}

}  // namespace
}  // namespace tofguard::test
