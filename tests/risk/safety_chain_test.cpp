// tofguard-discrepancy and tofguard-risk together as real processes over
// real LCM (private network namespace), fed synthetic camera, rendered and
// label frames at 30 Hz with the simulated camera's noise: noise-only
// frames stay SAFE, an object in front of the arm becomes UNKNOWN_OBJECT, a
// dead renderer becomes COMPONENT_FAULT by itself.
#include <gtest/gtest.h>

#include "chain_bus.hpp"
#include "synthetic_frames.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/joint_state_t.hpp"

namespace tofguard::test {
namespace {

const auto kDeadline = std::chrono::seconds(10);

class SafetyChain : public ::testing::Test {
 protected:
  void SetUp() override {
    // Its frames are made here, an ideal camera's of other intrinsics.
    const std::string config = ideal_camera_config("chain");
    discrepancy_ = std::make_unique<Subprocess>(
        "chain-discrepancy",
        std::vector<std::string>{bin_dir() + "/tofguard-discrepancy", "--config", config});
    risk_ = std::make_unique<Subprocess>(
        "chain-risk", std::vector<std::string>{bin_dir() + "/tofguard-risk", "--config", config});
    ASSERT_TRUE(wait_until(
        [&] {
          return !bus_.last_heartbeat("tofguard-risk").process.empty() &&
                 !bus_.last_heartbeat("tofguard-discrepancy").process.empty();
        },
        kDeadline, [&] { bus_.poll(); }));
  }
  void TearDown() override {
    for (auto* p : {discrepancy_.get(), risk_.get()}) {
      p->signal(SIGTERM);
      EXPECT_EQ(p->wait(std::chrono::seconds(5)), 0) << p->stderr_text();
    }
  }

  // One camera period: joint state, heartbeats of the camera and (when
  // alive) the renderer, the camera frame of `scene`, and (when alive) the
  // rendered frame and labels of the model.
  void step(const std::vector<Box>& scene, bool renderer_alive = true) {
    joint_state_t joints{};
    joints.utime = wall_utime();  // a newer one each period (an old one is refused)
    joints.robot_id = "friend-sim";
    joints.num_joints = 1;
    joints.name = {"a1"};
    joints.position = {0.2};
    joints.velocity = {0.3};
    bus_.safety.publish("JOINT_STATE", &joints);
    bus_.beat("tofguard-camera");
    ++seq_;
    const depth_image_t camera =
        depth_frame(with_noise(draw(scene).depth_mm, static_cast<uint32_t>(seq_)), seq_);
    bus_.images.publish("TOF_DEPTH", &camera);
    if (!renderer_alive) return;
    bus_.beat("tofguard-renderer");
    const SyntheticImage model = draw(default_arm());
    const depth_image_t rendered = depth_frame(model.depth_mm, seq_);
    const link_labels_t labels = labels_frame(model.label, seq_);
    bus_.images.publish("TOF_RENDERED", &rendered);
    bus_.images.publish("TOF_LABELS", &labels);
  }

  const risk_t* risk_for(int64_t seq) const {
    for (const auto& r : bus_.risks.messages) {
      if (r.seq == seq) return &r;
    }
    return nullptr;
  }

  ChainBus bus_;
  std::unique_ptr<Subprocess> discrepancy_;
  std::unique_ptr<Subprocess> risk_;
  int64_t seq_ = 0;
};

TEST_F(SafetyChain, NoiseStaysSafeAnObjectIsDangerousADeadRendererIsAComponentFault) {
  // 1 s of nominal frames: every frame judged SAFE.
  ASSERT_TRUE(run_until(
      bus_, [&] { return risk_for(30) != nullptr; }, kDeadline, 33, [&] { step(default_arm()); }));
  for (int64_t seq = 2; seq <= 30; ++seq) {
    const risk_t* r = risk_for(seq);
    ASSERT_NE(r, nullptr) << seq;
    EXPECT_EQ(r->level, risk_t::SAFE) << seq << ": " << r->detail;
  }

  // An object 0.1 m in front of the arm: DANGEROUS on the third frame.
  std::vector<Box> with_object = default_arm();
  with_object.push_back({30, 110, 50, 130, 1400, 0});
  const int64_t first_object = seq_ + 1;
  ASSERT_TRUE(run_until(
      bus_, [&] { return risk_for(first_object + 2) != nullptr; }, kDeadline, 33,
      [&] { step(with_object); }));
  EXPECT_EQ(risk_for(first_object)->level, risk_t::WARNING);
  EXPECT_EQ(risk_for(first_object + 2)->level, risk_t::DANGEROUS);
  EXPECT_EQ(risk_for(first_object + 2)->cause, risk_t::CAUSE_UNKNOWN_OBJECT);

  // Back to nominal: the stop's diagnosis stays open (DANGEROUS, the same
  // cause) until risk.evidence.clear_frames (10 in config/sim.yaml) nominal
  // frames in a row; the 10th is SAFE. Then the renderer dies: no rendered
  // frames, no heartbeat. The chain reports it by itself.
  const int64_t first_nominal = seq_ + 1;
  auto first_safe = [&]() -> int64_t {
    for (const risk_t& r : bus_.risks.messages) {
      if (r.seq >= first_nominal && r.level == risk_t::SAFE) return r.seq;
    }
    return -1;
  };
  ASSERT_TRUE(run_until(
      bus_, [&] { return first_safe() >= 0; }, kDeadline, 33, [&] { step(default_arm()); }));
  EXPECT_GE(first_safe(), first_nominal + 9);
  for (int64_t seq = first_nominal; seq < first_safe(); ++seq) {
    if (const risk_t* open = risk_for(seq)) {
      EXPECT_EQ(open->level, risk_t::DANGEROUS) << seq;
      EXPECT_EQ(open->cause, risk_t::CAUSE_UNKNOWN_OBJECT) << seq;
    }
  }
  const size_t before = bus_.risks.messages.size();
  const int64_t last_rendered = seq_;
  int64_t first_unrendered_us = 0;
  auto component_fault = [&]() -> int {
    for (size_t i = before; i < bus_.risks.messages.size(); ++i) {
      const risk_t& r = bus_.risks.messages[i];
      if (r.level == risk_t::DANGEROUS && r.cause == risk_t::CAUSE_COMPONENT_FAULT)
        return static_cast<int>(i);
    }
    return -1;
  };
  ASSERT_TRUE(run_until(
      bus_, [&] { return component_fault() >= 0; }, kDeadline, 33,
      [&] {
        if (first_unrendered_us == 0) first_unrendered_us = monotonic_us();
        step(default_arm(), /*renderer_alive=*/false);
      }));
  const int i = component_fault();
  EXPECT_EQ(bus_.risks.messages[i].suspect, "tofguard-renderer");
  // Within 200 ms of the first camera frame the renderer missed (pairing
  // waits 100 ms; two unusable frames debounce), with some slack for load.
  EXPECT_LE(bus_.risks.arrival_us[i] - first_unrendered_us, 300'000);
  // No frame after the renderer died was judged SAFE.
  for (size_t k = before; k < bus_.risks.messages.size(); ++k) {
    if (bus_.risks.messages[k].seq > last_rendered) {
      EXPECT_NE(bus_.risks.messages[k].level, risk_t::SAFE) << bus_.risks.messages[k].detail;
    }
  }
}

}  // namespace
}  // namespace tofguard::test
