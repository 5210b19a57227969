// tofguard-risk as a real process over real LCM (private network
// namespace): verdicts per frame, debouncing, timeouts that fire by
// themselves within their deadline, and malformed input on every channel
// dropped and counted while good frames are still judged.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "chain_bus.hpp"
#include "signed_publisher.hpp"
#include "synthetic_estimates.hpp"
#include "synthetic_frames.hpp"
#include "tofguard/auth/message_verifier.hpp"
#include "tofguard/authenticated_message_t.hpp"
#include "tofguard/camera_pose_t.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/speed_limit_t.hpp"

namespace tofguard::test {
namespace {

const auto kDeadline = std::chrono::seconds(10);
constexpr int kFramePeriodMs = 33;

discrepancy_t summary(int64_t seq, int shift_px) {
  const SyntheticImage model = draw(default_arm());
  const deployment::Config config = deployment::load_config(ideal_camera_config(), nullptr);
  return discrepancy::compute_discrepancy(
             depth_frame(with_noise(draw(default_arm(shift_px)).depth_mm, seq), seq),
             depth_frame(model.depth_mm, seq), labels_frame(model.label, seq),
             discrepancy::discrepancy_options(config.discrepancy))
      .summary;
}

joint_state_t moving_arm() {
  joint_state_t s{};
  s.utime = wall_utime();
  s.robot_id = "friend-sim";
  for (int i = 1; i <= 7; ++i) {
    s.name.push_back("a" + std::to_string(i));
    s.position.push_back(0.1 * i);
    s.velocity.push_back(0.3);
  }
  s.num_joints = 7;
  return s;
}

class RiskProcess : public ::testing::Test {
 protected:
  void SetUp() override {
    good_ = summary(1, 0);
    shifted_ = summary(1, 16);
    process_ = std::make_unique<Subprocess>(
        "risk-process",
        std::vector<std::string>{
            bin_dir() + "/tofguard-risk", "--config",
            // these tests watch the wait; their synthetic
            // frames carry no user (risk_logic_test judges
            // the user's)
            sim_config_variant("chain-risk", {{"    wait_ms: 0\n", "    wait_ms: 60\n"}}, "occupant: ~\n")});
    ASSERT_TRUE(wait_until([&] { return !bus_.last_heartbeat("tofguard-risk").process.empty(); }, kDeadline,
                           [&] { bus_.poll(); }))
        << process_->stderr_text();
  }
  void TearDown() override {
    process_->signal(SIGTERM);
    EXPECT_EQ(process_->wait(std::chrono::seconds(5)), 0) << process_->stderr_text();
  }

  // One camera period of healthy inputs; the frame's summary is `frame`
  // with the next seq (none when `camera` is false: a stalled camera).
  void step(const discrepancy_t& frame, bool camera = true, bool renderer_beats = true) {
    const joint_state_t joints = moving_arm();
    bus_.safety.publish("JOINT_STATE", &joints);
    bus_.beat("tofguard-camera");
    bus_.beat("tofguard-discrepancy");
    if (renderer_beats) bus_.beat("tofguard-renderer");
    if (!camera) return;
    ++seq_;
    depth_image_t image = depth_frame({500, 600, 700, 800}, seq_, 2, 2);
    bus_.images.publish("TOF_DEPTH", &image);
    last_depth_us_ = monotonic_us();
    discrepancy_t d = frame;
    d.seq = seq_;
    d.utime = image.utime;
    bus_.safety.publish("SAFETY_DISCREPANCY", &d);
    if (estimate_) {
      const motion_estimate_t e = estimate_(d);
      bus_.safety.publish("MOTION_ESTIMATE", &e);
    }
  }

  const risk_t* risk_for(int64_t seq) const {
    for (const auto& r : bus_.risks.messages) {
      if (r.seq == seq) return &r;
    }
    return nullptr;
  }

  // Feeds `frame` every period until the verdict for seq `seq` arrived.
  bool feed_until_judged(const discrepancy_t& frame, int64_t seq) {
    return run_until(
        bus_, [&] { return risk_for(seq) != nullptr; }, kDeadline, kFramePeriodMs, [&] { step(frame); });
  }

  ChainBus bus_;
  std::unique_ptr<Subprocess> process_;
  discrepancy_t good_;
  discrepancy_t shifted_;
  int64_t seq_ = 0;
  int64_t last_depth_us_ = 0;
  // When set, the estimator's answer to each frame, published right after
  // its discrepancy.
  std::function<motion_estimate_t(const discrepancy_t&)> estimate_;
};

TEST_F(RiskProcess, StartsDangerousBecauseNothingHasArrived) {
  ASSERT_TRUE(wait_until([&] { return !bus_.risks.messages.empty(); }, kDeadline, [&] { bus_.poll(); }));
  const risk_t& r = bus_.risks.messages.front();
  EXPECT_EQ(r.seq, -1);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.cause, risk_t::CAUSE_SENSOR_FAULT);
  // The first deadline to expire: joint state 100 ms (depth 150 ms).
  EXPECT_EQ(r.suspect, "JOINT_STATE");
}

TEST_F(RiskProcess, GoodFramesAreSafeAndAJointErrorIsDangerousAfterTheDebounce) {
  ASSERT_TRUE(feed_until_judged(good_, 5));
  for (int64_t seq = 2; seq <= 5; ++seq) {
    ASSERT_NE(risk_for(seq), nullptr) << seq;
    EXPECT_EQ(risk_for(seq)->level, risk_t::SAFE) << risk_for(seq)->detail;
    EXPECT_EQ(risk_for(seq)->utime, depth_frame({}, seq).utime);  // the frame's (old) utime
  }
  ASSERT_TRUE(feed_until_judged(shifted_, 8));
  EXPECT_EQ(risk_for(6)->level, risk_t::WARNING);
  EXPECT_EQ(risk_for(7)->level, risk_t::WARNING);
  EXPECT_EQ(risk_for(8)->level, risk_t::DANGEROUS);
  EXPECT_EQ(risk_for(8)->cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(risk_for(8)->suspect, "a2");
}

TEST_F(RiskProcess, TheMotionEstimateNamesTheSuspectJointAndItsOffset) {
  ASSERT_TRUE(feed_until_judged(good_, 3));
  estimate_ = [](const discrepancy_t& d) {
    motion_estimate_t e = estimate_for(d);
    e.estimated_position[index_of(e, "a4")] -= 12.3 * kDeg;
    return e;
  };
  ASSERT_TRUE(feed_until_judged(shifted_, 6));
  for (int64_t seq = 4; seq <= 6; ++seq) {
    const risk_t* r = risk_for(seq);
    EXPECT_EQ(r->cause, risk_t::CAUSE_JOINT_ERROR);
    EXPECT_EQ(r->suspect, "a4");  // the discrepancy rules alone say a2
    EXPECT_EQ(r->detail.rfind("joint a4 reads 12.3° more than seen", 0), 0u) << r->detail;
    EXPECT_NEAR(r->score, 12.3, 1e-9);
  }
  EXPECT_EQ(risk_for(5)->level, risk_t::WARNING);
  EXPECT_EQ(risk_for(6)->level, risk_t::DANGEROUS);

  // A camera correction instead: a calibration error for this frame, but
  // the stop's diagnosis stays open with its cause and suspect (the frame's
  // own finding is in the detail).
  estimate_ = [](const discrepancy_t& d) {
    motion_estimate_t e = estimate_for(d);
    e.correction_translation[1] = 0.048;
    return e;
  };
  // (Frames published while the last one waited had the old estimate.)
  const int64_t calibration_seq = seq_ + 1;
  ASSERT_TRUE(feed_until_judged(shifted_, calibration_seq));
  const risk_t* r = risk_for(calibration_seq);
  EXPECT_EQ(r->level, risk_t::DANGEROUS);
  EXPECT_EQ(r->cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(r->suspect, "a4");
  EXPECT_EQ(r->detail.rfind("diagnosis open since seq 6: joint a4 reads 12.3° more than seen", 0), 0u)
      << r->detail;
  EXPECT_NE(r->detail.find("this frame: camera pose off by 4.8 cm and 0.0° (seen vs configured"),
            std::string::npos)
      << r->detail;
}

TEST_F(RiskProcess, WithoutAnEstimateTheDiscrepancyRulesJudgeAfterTheWait) {
  ASSERT_TRUE(feed_until_judged(good_, 2));
  ASSERT_TRUE(feed_until_judged(shifted_, 5));
  for (int64_t seq = 3; seq <= 5; ++seq) {
    EXPECT_EQ(risk_for(seq)->cause, risk_t::CAUSE_JOINT_ERROR);
    EXPECT_EQ(risk_for(seq)->suspect, "a2");
    EXPECT_NE(risk_for(seq)->detail.find("(no motion estimate within 60 ms)"), std::string::npos)
        << risk_for(seq)->detail;
  }
  EXPECT_EQ(risk_for(5)->level, risk_t::DANGEROUS);
  // An unusable estimate changes nothing either.
  estimate_ = [](const discrepancy_t& d) {
    motion_estimate_t e = estimate_for(d);
    e.usable = false;
    e.unusable_reason = "too few model points visible";
    return e;
  };
  // (Frames published while the last one waited had no estimate.)
  const int64_t unusable_seq = seq_ + 1;
  ASSERT_TRUE(feed_until_judged(shifted_, unusable_seq));
  const risk_t* r = risk_for(unusable_seq);
  EXPECT_EQ(r->suspect, "a2");
  EXPECT_NE(r->detail.find("estimate explains nothing: unusable, too few model points visible"),
            std::string::npos)
      << r->detail;
  EXPECT_EQ(r->level, risk_t::DANGEROUS);
}

TEST_F(RiskProcess, TheArmLeavingItsPlanIsAFinding) {
  ASSERT_TRUE(feed_until_judged(good_, 2));
  // The plan holds every joint at moving_arm()'s positions, but a1 0.2 rad
  // (11.5 deg) further.
  planned_trajectory_t plan{};
  plan.utime = wall_utime();
  for (int i = 1; i <= 7; ++i) plan.joint_name.push_back("a" + std::to_string(i));
  plan.num_joints = 7;
  plan.point_utime = {plan.utime - 1'000'000, plan.utime + 60'000'000};
  plan.num_points = 2;
  for (int p = 0; p < 2; ++p) {
    plan.position.emplace_back();
    for (int i = 1; i <= 7; ++i) plan.position.back().push_back(0.1 * i + (i == 1 ? 0.2 : 0.0));
  }
  bus_.safety.publish("PLANNED_TRAJECTORY", &plan);
  ASSERT_TRUE(run_until(
      bus_,
      [&] {
        return !bus_.risks.messages.empty() && bus_.risks.messages.back().level == risk_t::DANGEROUS &&
               bus_.risks.messages.back().seq >= 0;
      },
      kDeadline, kFramePeriodMs, [&] { step(good_); }));
  const risk_t& r = bus_.risks.messages.back();
  EXPECT_EQ(r.cause, risk_t::CAUSE_UNCLASSIFIED);
  EXPECT_EQ(r.suspect, "a1");
  EXPECT_EQ(r.detail.rfind("arm left its plan (deg): a1 is 11.5° from the plan", 0), 0u) << r.detail;
  // Back on the plan (a new one where the arm is): safe again.
  for (auto& point : plan.position) point[0] = 0.1;
  plan.utime = wall_utime();
  plan.point_utime = {plan.utime - 1'000'000, plan.utime + 60'000'000};
  bus_.safety.publish("PLANNED_TRAJECTORY", &plan);
  ASSERT_TRUE(run_until(
      bus_, [&] { return !bus_.risks.messages.empty() && bus_.risks.messages.back().level == risk_t::SAFE; },
      kDeadline, kFramePeriodMs, [&] { step(good_); }));
}

TEST_F(RiskProcess, CameraStallTimesOutByItselfWithinTheDeadline) {
  ASSERT_TRUE(feed_until_judged(good_, 5));
  const size_t before = bus_.risks.messages.size();
  auto stall_verdict = [&]() -> int {
    for (size_t i = before; i < bus_.risks.messages.size(); ++i) {
      if (bus_.risks.messages[i].seq == -1) return static_cast<int>(i);
    }
    return -1;
  };
  // Joint state and heartbeats go on; the camera (and so the chain) stops.
  ASSERT_TRUE(run_until(
      bus_, [&] { return stall_verdict() >= 0; }, kDeadline, kFramePeriodMs,
      [&] { step(good_, /*camera=*/false); }));
  const risk_t& r = bus_.risks.messages[stall_verdict()];
  const int64_t after_us = bus_.risks.arrival_us[stall_verdict()] - last_depth_us_;
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(r.suspect, "TOF_DEPTH");
  EXPECT_EQ(r.utime, depth_frame({}, 5).utime);
  // risk.deadlines_ms.depth = 150: not before it, and well within 200 ms of it.
  EXPECT_GE(after_us, 150'000);
  EXPECT_LE(after_us, 300'000);
}

// The controller's speed limit (speed_limit_t): one per frame taken, with
// its seq, and 0 m/s with every timeout; each also signed on
// SAFETY_SPEED_LIMIT_AUTH with the deployment's key.
TEST_F(RiskProcess, EveryFrameAndEveryTimeoutGivesTheControllerASignedSpeedLimit) {
  Inbox<speed_limit_t> limits;
  Inbox<authenticated_message_t> signed_limits;
  bus_.safety.subscribe("SAFETY_SPEED_LIMIT", &Inbox<speed_limit_t>::on_message, &limits);
  bus_.safety.subscribe("SAFETY_SPEED_LIMIT_AUTH", &Inbox<authenticated_message_t>::on_message,
                        &signed_limits);
  // Before any frame: the deadlines' timeouts, each with a limit of 0.
  ASSERT_TRUE(wait_until([&] { return !limits.messages.empty(); }, kDeadline, [&] { bus_.poll(); }));
  EXPECT_EQ(limits.messages.front().seq, -1);
  EXPECT_EQ(limits.messages.front().set_by, speed_limit_t::SET_BY_NO_JUDGEMENT);
  EXPECT_DOUBLE_EQ(limits.messages.front().max_arm_speed_m_s, 0);
  EXPECT_EQ(limits.messages.front().reason.rfind("stand: ", 0), 0u) << limits.messages.front().reason;

  // Frames with the arm's cover and nothing unexplained: the range (2 m)
  // sets the limit, (2 - S at rest 0.779 m) / T_r 0.193 s = 6.31 m/s.
  discrepancy_t frame = good_;
  frame.field_available = true;
  frame.field_bin_m = 0.01f;
  frame.num_field_bins = 200;
  frame.unexplained_area_within_m2.assign(200, 0.0f);
  ASSERT_TRUE(feed_until_judged(frame, 5));
  ASSERT_TRUE(wait_until(
      [&] {
        return std::any_of(limits.messages.begin(), limits.messages.end(),
                           [](const speed_limit_t& l) { return l.seq == 5; });
      },
      kDeadline, [&] { bus_.poll(); }));
  for (int64_t seq = 1; seq <= 5; ++seq) {
    const auto it = std::find_if(limits.messages.begin(), limits.messages.end(),
                                 [&](const speed_limit_t& l) { return l.seq == seq; });
    ASSERT_NE(it, limits.messages.end()) << "no limit for frame " << seq;
    EXPECT_EQ(it->set_by, speed_limit_t::SET_BY_RANGE) << it->reason;
    EXPECT_NEAR(it->max_arm_speed_m_s, 6.31, 0.01) << it->reason;
    EXPECT_EQ(it->valid_for_ms, 150);
    EXPECT_EQ(it->camera_id, "tof-mast");
  }
  // The signed copies open with the deployment's key, each a limit sent.
  const deployment::Config config = deployment::load_config(chain_config("risk-key"), nullptr);
  auth::MessageVerifier verifier(config.auth.key, config.auth.max_age_us);
  ASSERT_FALSE(signed_limits.messages.empty());
  int opened = 0;
  for (size_t i = 0; i < signed_limits.messages.size(); ++i) {
    std::string refusal;
    const std::optional<speed_limit_t> limit = verifier.open<speed_limit_t>(
        signed_limits.messages[i], "SAFETY_SPEED_LIMIT", signed_limits.messages[i].utime, &refusal);
    ASSERT_TRUE(limit.has_value()) << refusal;
    ++opened;
    if (limit->seq == 5) {
      EXPECT_NEAR(limit->max_arm_speed_m_s, 6.31, 0.01);
    }
  }
  EXPECT_EQ(opened, static_cast<int>(signed_limits.messages.size()));
}

// The speed-scaling controller's example (auth/examples/follow_speed_limit
// .cpp) on the live stream: it caps its speed at the verified limit while a
// verified status allows motion, and at 0 before.
TEST_F(RiskProcess, TheControllerExampleFollowsTheVerifiedLimit) {
  // A person 0.9 m from the arm: 0.62 m/s, below the example's 0.7.
  discrepancy_t frame = good_;
  frame.field_available = true;
  frame.field_bin_m = 0.01f;
  frame.num_field_bins = 200;
  frame.unexplained_area_within_m2.assign(200, 0.0f);
  for (int k = 89; k < 200; ++k) frame.unexplained_area_within_m2[k] = 0.01f;
  Subprocess controller("follow-speed-limit", {bin_dir() + "/tofguard-follow-speed-limit-example", "--key",
                                               default_key_file(), "--url", kSafetyUrl, "--desired-m-s",
                                               "0.7", "--count", "20", "--timeout-ms", "3000"});
  SignedPublisher intervene(bus_.safety);
  safety_status_t allowed{};
  allowed.motion_allowed = true;
  allowed.reason = "test: motion allowed";
  int steps = 0;
  ASSERT_TRUE(run_until(
      bus_, [&] { return !controller.running(); }, kDeadline, kFramePeriodMs,
      [&] {
        step(frame);
        // The permission starts after the fifth frame.
        if (++steps > 5) {
          allowed.utime = wall_utime();
          ++allowed.seq;
          intervene.publish("SAFETY_STATUS", allowed);
        }
      }))
      << controller.stdout_text();
  EXPECT_EQ(controller.wait(std::chrono::seconds(1)), 0) << controller.stderr_text();
  const std::string seen = controller.stdout_text();
  EXPECT_NE(seen.find("max=0.62 set_by=1 -> cap 0.62 (the limit)"), std::string::npos) << seen;
  EXPECT_NE(seen.find("-> cap 0.00 (no fresh status allowing motion)"), std::string::npos) << seen;
  EXPECT_EQ(seen.find("refused"), std::string::npos) << seen;
}

TEST_F(RiskProcess, MissingHeartbeatIsAComponentFault) {
  ASSERT_TRUE(feed_until_judged(good_, 3));
  ASSERT_TRUE(run_until(
      bus_,
      [&] {
        return !bus_.risks.messages.empty() &&
               bus_.risks.messages.back().cause == risk_t::CAUSE_COMPONENT_FAULT;
      },
      kDeadline, kFramePeriodMs, [&] { step(good_, true, /*renderer_beats=*/false); }));
  EXPECT_EQ(bus_.risks.messages.back().suspect, "tofguard-renderer");
  EXPECT_EQ(bus_.risks.messages.back().level, risk_t::DANGEROUS);
}

TEST_F(RiskProcess, MalformedInputOnEveryChannelIsDroppedAndCounted) {
  ASSERT_TRUE(feed_until_judged(good_, 2));
  // SAFETY_DISCREPANCY: inconsistent (validation), another type (decode).
  discrepancy_t bad = good_;
  bad.seq = 1000;
  bad.num_robot_links = 99;
  bus_.safety.publish("SAFETY_DISCREPANCY", &bad);
  const joint_state_t not_a_discrepancy = moving_arm();
  bus_.safety.publish("SAFETY_DISCREPANCY", &not_a_discrepancy);
  // TOF_DEPTH: num_pixels != width*height (validation).
  depth_image_t wrong_size = depth_frame({1, 2, 3, 4}, 1000, 2, 2);
  wrong_size.num_pixels = 3;
  wrong_size.depth_mm.resize(3);
  bus_.images.publish("TOF_DEPTH", &wrong_size);
  // JOINT_STATE: NaN, unknown joint (validation), truncated (decode).
  joint_state_t nan_joint = moving_arm();
  nan_joint.position[3] = std::nan("");
  bus_.safety.publish("JOINT_STATE", &nan_joint);
  joint_state_t unknown = moving_arm();
  unknown.name[6] = "a8";
  bus_.safety.publish("JOINT_STATE", &unknown);
  std::vector<uint8_t> bytes(unknown.getEncodedSize());
  unknown.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  bus_.safety.publish("JOINT_STATE", bytes.data(), static_cast<unsigned>(bytes.size() - 9));
  // CAMERA_POSE: non-unit quaternion (validation).
  camera_pose_t pose{};
  pose.utime = 1;
  pose.camera_id = "tof-mast";
  pose.frame_id = "world";
  pose.rotation[0] = 2;
  bus_.safety.publish("CAMERA_POSE", &pose);
  // SAFETY_HEARTBEAT: no process name (validation), another type (decode).
  heartbeat_t nameless{};
  bus_.safety.publish("SAFETY_HEARTBEAT", &nameless);
  bus_.safety.publish("SAFETY_HEARTBEAT", &pose);
  // MOTION_ESTIMATE: NaN estimate (validation), another camera
  // (validation). PLANNED_TRAJECTORY: times not increasing (validation).
  motion_estimate_t estimate = estimate_for(good_);
  estimate.estimated_position[2] = std::nan("");
  bus_.safety.publish("MOTION_ESTIMATE", &estimate);
  estimate = estimate_for(good_);
  estimate.camera_id = "another-camera";
  bus_.safety.publish("MOTION_ESTIMATE", &estimate);
  planned_trajectory_t plan{};
  plan.num_joints = 1;
  plan.joint_name = {"a1"};
  plan.num_points = 2;
  plan.point_utime = {1000, 1000};
  plan.position = {{0.0}, {0.1}};
  bus_.safety.publish("PLANNED_TRAJECTORY", &plan);

  // Good frames are still judged, and nothing came of seq 1000.
  ASSERT_TRUE(feed_until_judged(good_, 4));
  EXPECT_EQ(risk_for(4)->level, risk_t::SAFE) << risk_for(4)->detail;
  EXPECT_EQ(risk_for(1000), nullptr);
  ASSERT_TRUE(wait_until(
      [&] {
        const heartbeat_t hb = bus_.last_heartbeat("tofguard-risk");
        return hb.decode_errors == 3 && hb.validation_errors == 9;
      },
      kDeadline, [&] { bus_.poll(); }))
      << "decode " << bus_.last_heartbeat("tofguard-risk").decode_errors << " validation "
      << bus_.last_heartbeat("tofguard-risk").validation_errors << "\n"
      << process_->stderr_text();
  EXPECT_TRUE(process_->running());
  EXPECT_NE(process_->stderr_text().find("JOINT_STATE: position[3] (a4): expected a finite number"),
            std::string::npos)
      << process_->stderr_text();
  EXPECT_NE(
      process_->stderr_text().find("MOTION_ESTIMATE: estimated_position[2] (a3): expected a finite number"),
      std::string::npos)
      << process_->stderr_text();
}

// Fault injection (clock jumps, duplicates, out-of-order seq): a frame
// judged once is never judged again, an older one or one whose camera clock
// went back is refused, and a joint driver stuck resending its last state
// goes stale. Each refusal is counted (frames_dropped) and reported.
TEST_F(RiskProcess, DuplicateOutOfOrderAndClockJumpedInputsAreRefusedAndCounted) {
  ASSERT_TRUE(feed_until_judged(good_, 5));
  auto verdicts_for = [&](int64_t seq) {
    int n = 0;
    for (const auto& r : bus_.risks.messages) n += r.seq == seq;
    return n;
  };
  auto frame = [&](int64_t seq, int64_t utime) {
    discrepancy_t d = good_;
    d.seq = seq;
    d.utime = utime;
    bus_.safety.publish("SAFETY_DISCREPANCY", &d);
  };
  ASSERT_TRUE(wait_until([&] { return bus_.last_heartbeat("tofguard-risk").utime > 0; }, kDeadline,
                         [&] { bus_.poll(); }));
  const int64_t dropped_before = bus_.last_heartbeat("tofguard-risk").frames_dropped;
  frame(5, depth_frame({}, 5).utime);               // a duplicate
  frame(3, depth_frame({}, 3).utime);               // an older seq
  frame(6, depth_frame({}, 5).utime - 10'000'000);  // the camera's clock set back 10 s
  seq_ = 6;
  ASSERT_TRUE(feed_until_judged(good_, 9));
  EXPECT_EQ(verdicts_for(5), 1);
  EXPECT_EQ(verdicts_for(3), 1);
  EXPECT_EQ(verdicts_for(6), 0);
  EXPECT_EQ(risk_for(9)->level, risk_t::SAFE) << risk_for(9)->detail;
  ASSERT_TRUE(
      wait_until([&] { return bus_.last_heartbeat("tofguard-risk").frames_dropped - dropped_before == 3; },
                 kDeadline, [&] { bus_.poll(); }))
      << bus_.last_heartbeat("tofguard-risk").frames_dropped - dropped_before << "\n"
      << process_->stderr_text();
  EXPECT_NE(process_->stderr_text().find("SAFETY_DISCREPANCY: refused: frame seq 5"), std::string::npos)
      << process_->stderr_text();

  // A camera clock jumping forward: the frame is newer, judged.
  frame(10, depth_frame({}, 9).utime + 10'000'000);
  ASSERT_TRUE(wait_until([&] { return verdicts_for(10) == 1; }, kDeadline, [&] { bus_.poll(); }));

  // A joint driver stuck resending the same state (same utime) while
  // everything else is fresh: JOINT_STATE goes stale within its deadline.
  joint_state_t stuck = moving_arm();
  const size_t verdicts_before = bus_.risks.messages.size();
  int64_t first_stuck_us = 0;
  int64_t seq = 100;  // newer than the jumped frame's seq
  int64_t utime = depth_frame({}, 9).utime + 10'100'000;
  auto stale_joints = [&] {
    for (size_t i = verdicts_before; i < bus_.risks.messages.size(); ++i) {
      const risk_t& r = bus_.risks.messages[i];
      if (r.level == risk_t::DANGEROUS && r.suspect == "JOINT_STATE") return bus_.risks.arrival_us[i];
    }
    return int64_t{0};
  };
  ASSERT_TRUE(run_until(
      bus_, [&] { return stale_joints() > 0; }, kDeadline, 10,
      [&] {
        bus_.safety.publish("JOINT_STATE", &stuck);
        if (first_stuck_us == 0) first_stuck_us = monotonic_us();
        bus_.beat("tofguard-camera");
        bus_.beat("tofguard-discrepancy");
        bus_.beat("tofguard-renderer");
        depth_image_t image = depth_frame({500, 600, 700, 800}, ++seq, 2, 2);
        bus_.images.publish("TOF_DEPTH", &image);
        frame(seq, utime += 10'000);
      }))
      << process_->stderr_text();
  const int64_t latency = stale_joints() - first_stuck_us;
  std::cout << "joint driver resending its last state: JOINT_STATE stale " << latency / 1000.0
            << " ms after the first copy" << std::endl;
  EXPECT_LE(latency, 100'000 + 200'000);
  EXPECT_NE(process_->stderr_text().find("JOINT_STATE: refused: joint state utime"), std::string::npos)
      << process_->stderr_text();
}

}  // namespace
}  // namespace tofguard::test
