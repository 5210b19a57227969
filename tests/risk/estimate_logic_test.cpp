// The risk classifier with motion estimates and plans: classify_estimate on
// synthetic estimates, the wait for a frame's estimate on an explicit
// monotonic clock (fail safe: never safer), the arm leaving its plan, and
// the wire checks of motion_estimate_t and planned_trajectory_t.
#include <gtest/gtest.h>

#include <cmath>

#include "synthetic_estimates.hpp"
#include "synthetic_frames.hpp"
#include "tofguard/common/planned_trajectory.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/risk/estimate_finding.hpp"
#include "tofguard/risk/risk_monitor.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

using risk::classify_estimate;
using risk::EstimateContext;
using risk::FrameFinding;
using risk::RiskMonitor;

constexpr int64_t kStart = 5'000'000'000;  // monotonic
constexpr double kRateHz = 30;             // camera.rate_hz of config/sim.yaml
constexpr int64_t kMs = 1000;

// config/sim.yaml with a 60 ms wait for a frame's own estimate (sim.yaml
// waits 0 ms; these tests are about the wait).
const deployment::Config& sim_config() {
  static const deployment::Config config = [] {
    deployment::Config c = deployment::load_config(ideal_camera_config(), nullptr);
    c.risk.estimate_wait_us = 60000;
    return c;
  }();
  return config;
}

const robot_model::KinematicTree& friend_arm() {
  static const robot_model::KinematicTree tree =
      robot_model::load_kinematic_tree(sim_config().robot.urdf_path);
  return tree;
}

discrepancy_t summary_of(const std::vector<Box>& camera_scene, int64_t seq) {
  const SyntheticImage model = draw(default_arm());
  const SyntheticImage seen = draw(camera_scene);
  return discrepancy::compute_discrepancy(depth_frame(with_noise(seen.depth_mm, 1), seq),
                                          depth_frame(model.depth_mm, seq), labels_frame(model.label, seq),
                                          discrepancy::discrepancy_options(sim_config().discrepancy))
      .summary;
}

motion_estimate_t synthetic_estimate() {
  discrepancy_t frame{};
  frame.utime = 1'700'000'000'000'000;
  frame.seq = 12;
  frame.camera_id = "tof-mast";
  return estimate_for(frame);
}

// ---- classify_estimate ----

TEST(ClassifyEstimate, NamesTheJointAndItsOffsetWithTheSignConvention) {
  motion_estimate_t e = synthetic_estimate();
  e.estimated_position[index_of(e, "a4")] += 12.3 * kDeg;  // seen further along than reported
  FrameFinding f = classify_estimate(e, sim_config().risk);
  EXPECT_EQ(f.cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(f.suspect, "a4");
  EXPECT_NEAR(f.score, 12.3, 1e-9);
  EXPECT_NEAR(f.threshold, 2.0, 1e-9);  // max(3 * 0.2 deg, 2 deg)
  EXPECT_EQ(f.detail.rfind("joint a4 reads 12.3° less than seen", 0), 0u) << f.detail;

  e = synthetic_estimate();
  e.estimated_position[index_of(e, "a2")] -= 5.0 * kDeg;
  f = classify_estimate(e, sim_config().risk);
  EXPECT_EQ(f.suspect, "a2");
  EXPECT_EQ(f.detail.rfind("joint a2 reads 5.0° more than seen", 0), 0u) << f.detail;
}

TEST(ClassifyEstimate, TheLargestNormalisedOffsetWinsAndUnobservableJointsAreNeverNamed) {
  motion_estimate_t e = synthetic_estimate();
  // a3: 8 deg but sigma 2 deg (threshold 6 deg, ratio 1.33); a5: 4 deg with
  // sigma 0.2 deg (threshold 2 deg, ratio 2): a5 wins.
  e.estimated_position[index_of(e, "a3")] += 8 * kDeg;
  e.position_sigma[index_of(e, "a3")] = 2 * kDeg;
  e.estimated_position[index_of(e, "a5")] += 4 * kDeg;
  EXPECT_EQ(classify_estimate(e, sim_config().risk).suspect, "a5");
  // a7: 30 deg, but unobservable.
  e.estimated_position[index_of(e, "a7")] += 30 * kDeg;
  e.observable[index_of(e, "a7")] = false;
  EXPECT_EQ(classify_estimate(e, sim_config().risk).suspect, "a5");
}

TEST(ClassifyEstimate, OffsetsBelowTheMinimumOrWithinTheSigmasAreNotSignificant) {
  motion_estimate_t e = synthetic_estimate();
  e.estimated_position[index_of(e, "a4")] += 1.9 * kDeg;  // < 2 deg minimum
  EXPECT_EQ(classify_estimate(e, sim_config().risk).cause, risk_t::CAUSE_NONE);
  e.estimated_position[index_of(e, "a4")] += 3.0 * kDeg;  // 4.9 deg
  e.position_sigma[index_of(e, "a4")] = 1.7 * kDeg;       // 3 sigma = 5.1 deg
  EXPECT_EQ(classify_estimate(e, sim_config().risk).cause, risk_t::CAUSE_NONE);
  e.position_sigma[index_of(e, "a4")] = 1.6 * kDeg;  // 3 sigma = 4.8 deg
  EXPECT_EQ(classify_estimate(e, sim_config().risk).suspect, "a4");
}

TEST(ClassifyEstimate, UnusableOrNotConvergedEstimatesNameNothing) {
  motion_estimate_t e = synthetic_estimate();
  e.estimated_position[index_of(e, "a4")] += 12 * kDeg;
  e.converged = false;
  EXPECT_EQ(classify_estimate(e, sim_config().risk).cause, risk_t::CAUSE_NONE);
  e.converged = true;
  e.usable = false;
  EXPECT_EQ(classify_estimate(e, sim_config().risk).cause, risk_t::CAUSE_NONE);
}

TEST(ClassifyEstimate, CameraCorrectionIsACalibrationError) {
  motion_estimate_t e = synthetic_estimate();
  e.correction_translation[0] = 0.0384;
  e.correction_translation[2] = -0.0288;  // 4.8 cm
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.4 * kDeg, Eigen::Vector3d(0, 1, 0)));
  e.correction_rotation[0] = q.w();
  e.correction_rotation[1] = q.x();
  e.correction_rotation[2] = q.y();
  e.correction_rotation[3] = q.z();
  // A base joint absorbing a little of it does not make it a joint error.
  e.estimated_position[index_of(e, "a1")] += 2.5 * kDeg;
  const FrameFinding f = classify_estimate(e, sim_config().risk);
  EXPECT_EQ(f.cause, risk_t::CAUSE_CALIBRATION_ERROR);
  EXPECT_EQ(f.suspect, "");
  EXPECT_NEAR(f.score, 4.8, 1e-9);  // cm
  EXPECT_NEAR(f.threshold, 2.0, 1e-9);
  EXPECT_EQ(f.detail.rfind("camera pose off by 4.8 cm and 0.4° (seen vs configured", 0), 0u) << f.detail;
  EXPECT_NE(f.detail.find("joint a1 also off by 2.5°"), std::string::npos) << f.detail;

  // A rotation alone (3 deg) is one too; 1 cm of translation alone is not.
  e = synthetic_estimate();
  const Eigen::Quaterniond r(Eigen::AngleAxisd(3 * kDeg, Eigen::Vector3d(1, 0, 0)));
  e.correction_rotation[0] = r.w();
  e.correction_rotation[1] = r.x();
  EXPECT_EQ(classify_estimate(e, sim_config().risk).cause, risk_t::CAUSE_CALIBRATION_ERROR);
  EXPECT_NEAR(classify_estimate(e, sim_config().risk).score, 3.0, 1e-9);
  e = synthetic_estimate();
  e.correction_translation[2] = 0.01;
  EXPECT_EQ(classify_estimate(e, sim_config().risk).cause, risk_t::CAUSE_NONE);
}

TEST(ClassifyEstimate, AJointErrorWinsOverASmallCameraCorrection) {
  motion_estimate_t e = synthetic_estimate();
  e.correction_translation[0] = 0.025;                   // ratio 1.25
  e.estimated_position[index_of(e, "a6")] -= 10 * kDeg;  // ratio 5
  const FrameFinding f = classify_estimate(e, sim_config().risk);
  EXPECT_EQ(f.cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(f.suspect, "a6");
}

TEST(ClassifyEstimate, NothingExplainedButAHighResidualOrSurfacesNearTheArmIsAnUnknownObject) {
  motion_estimate_t e = synthetic_estimate();
  e.residual_after_mm = 40;
  FrameFinding f = classify_estimate(e, sim_config().risk);
  EXPECT_EQ(f.cause, risk_t::CAUSE_UNKNOWN_OBJECT);
  EXPECT_DOUBLE_EQ(f.score, 40);
  EXPECT_DOUBLE_EQ(f.threshold, 25);
  e.residual_after_mm = 6;
  EXPECT_EQ(classify_estimate(e, sim_config().risk).cause, risk_t::CAUSE_NONE);
  EstimateContext near;
  near.near_arm_evidence = true;
  EXPECT_EQ(classify_estimate(e, sim_config().risk, near).cause, risk_t::CAUSE_UNKNOWN_OBJECT);
}

TEST(ClassifyEstimate, PrismaticJointsAreJudgedInMillimetres) {
  motion_estimate_t e = synthetic_estimate();
  e.estimated_position[index_of(e, "a3")] += 0.004;  // 4 mm: 0.23 deg if it were revolute
  e.position_sigma[index_of(e, "a3")] = 0.0002;
  EXPECT_EQ(classify_estimate(e, sim_config().risk).cause, risk_t::CAUSE_NONE);
  EstimateContext context;
  context.prismatic_joints = {"a3"};
  const FrameFinding f = classify_estimate(e, sim_config().risk, context);
  EXPECT_EQ(f.suspect, "a3");
  EXPECT_NEAR(f.score, 4.0, 1e-9);
  EXPECT_EQ(f.detail.rfind("joint a3 reads 4.0 mm less than seen", 0), 0u) << f.detail;
}

// ---- RiskMonitor: waiting for the estimate ----

heartbeat_t heartbeat(const std::string& process) {
  heartbeat_t hb{};
  hb.process = process;
  return hb;
}

joint_state_t joints_at(int64_t utime, double a1) {
  joint_state_t s{};
  s.utime = utime;
  s.num_joints = 1;
  s.name = {"a1"};
  s.position = {a1};
  s.velocity = {0};
  return s;
}

void feed_all(RiskMonitor* m, int64_t now) {
  m->on_depth(now);
  // A new state each time (a repeated one is refused as a duplicate), older
  // than the frames of these tests.
  m->on_joint_state(joints_at(1 + (now - kStart), 0), now);
  for (const char* p : {"tofguard-camera", "tofguard-renderer", "tofguard-discrepancy"}) {
    m->on_heartbeat(heartbeat(p), now);
  }
}

TEST(EstimateWait, AMismatchFrameWaitsForItsEstimateWhichNamesTheCause) {
  RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  feed_all(&m, kStart);
  const discrepancy_t bad = summary_of(default_arm(16), 100);  // discrepancy rules: JOINT_ERROR a2
  EXPECT_TRUE(m.on_frame(bad, kStart).empty());
  EXPECT_EQ(m.waiting_frames(), 1u);
  EXPECT_TRUE(m.release_due(kStart + 59 * kMs).empty());

  motion_estimate_t e = estimate_for(bad);
  e.estimated_position[index_of(e, "a4")] -= 12.3 * kDeg;
  const std::vector<risk_t> out = m.on_estimate(e, kStart + 20 * kMs);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].seq, 100);
  EXPECT_EQ(out[0].level, risk_t::WARNING);
  EXPECT_EQ(out[0].cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(out[0].suspect, "a4");
  EXPECT_EQ(out[0].detail.rfind("joint a4 reads 12.3° more than seen", 0), 0u) << out[0].detail;
  EXPECT_EQ(m.estimate_stats().used, 1);
}

// Frame `seq` of a joint error (a2 by the discrepancy rules) captured
// `after_us` after the first one's utime.
discrepancy_t mismatch_frame(int64_t seq, int64_t after_us) {
  discrepancy_t d = summary_of(default_arm(16), seq);
  d.utime = 1'700'000'000'000'000 + after_us;
  return d;
}

deployment::Config config_with_max_age() {
  deployment::Config config = sim_config();
  config.risk.estimate_max_age_us = 400000;
  return config;
}

TEST(EstimateWait, AFrameWithoutItsOwnEstimateUsesARecentOneAfterTheWait) {
  // The estimator takes longer than a frame period: the estimate of frame
  // 100 serves frame 101 (33 ms later) once 101's own wait is over, but not
  // frame 102, which is more than risk.estimate.max_age_ms after it.
  RiskMonitor m(config_with_max_age().risk, config_with_max_age().channels, friend_arm(), kRateHz, kStart);
  feed_all(&m, kStart);
  const discrepancy_t first = mismatch_frame(100, 0);
  EXPECT_TRUE(m.on_frame(first, kStart).empty());
  motion_estimate_t e = estimate_for(first);
  e.estimated_position[index_of(e, "a4")] -= 12.3 * kDeg;
  ASSERT_EQ(m.on_estimate(e, kStart + 20 * kMs).size(), 1u);

  const discrepancy_t second = mismatch_frame(101, 33'000);
  EXPECT_TRUE(m.on_frame(second, kStart + 33 * kMs).empty()) << "waits for its own estimate first";
  auto out = m.release_due(kStart + 94 * kMs);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].seq, 101);
  EXPECT_EQ(out[0].suspect, "a4");
  EXPECT_NE(out[0].detail.find("(estimate of frame 100, 33 ms earlier)"), std::string::npos) << out[0].detail;

  const discrepancy_t late = mismatch_frame(102, 500'000);
  feed_all(&m, kStart + 500 * kMs);
  EXPECT_TRUE(m.on_frame(late, kStart + 500 * kMs).empty());
  out = m.release_due(kStart + 561 * kMs);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].suspect, "a2") << "the discrepancy rules: " << out[0].detail;
  EXPECT_NE(out[0].detail.find("no motion estimate within 60 ms"), std::string::npos) << out[0].detail;
}

TEST(EstimateWait, AnEarlierFramesEstimateThatNamesNoJointOrCameraSaysNothingAboutThisFrame) {
  // An estimate of frame 100 that explains nothing and leaves a high
  // residual would, for frame 100 itself, mean an unknown object; for frame
  // 101 (a fault may have begun since) it is no evidence: the rules judge.
  RiskMonitor m(config_with_max_age().risk, config_with_max_age().channels, friend_arm(), kRateHz, kStart);
  feed_all(&m, kStart);
  const discrepancy_t first = mismatch_frame(100, 0);
  EXPECT_TRUE(m.on_frame(first, kStart).empty());
  motion_estimate_t e = estimate_for(first);
  e.residual_after_mm = 80;
  const auto own = m.on_estimate(e, kStart + 20 * kMs);
  ASSERT_EQ(own.size(), 1u);
  EXPECT_EQ(own[0].cause, risk_t::CAUSE_UNKNOWN_OBJECT) << own[0].detail;

  const discrepancy_t second = mismatch_frame(101, 33'000);
  EXPECT_TRUE(m.on_frame(second, kStart + 33 * kMs).empty());
  const auto out = m.release_due(kStart + 94 * kMs);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].cause, risk_t::CAUSE_JOINT_ERROR) << out[0].detail;
  EXPECT_EQ(out[0].suspect, "a2") << out[0].detail;
}

TEST(EstimateWait, WithoutAnEstimateTheDiscrepancyRulesJudgeAfterTheWaitAndFramesKeepTheirOrder) {
  RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  feed_all(&m, kStart);
  const discrepancy_t bad = summary_of(default_arm(16), 100);
  const discrepancy_t good = summary_of(default_arm(), 101);
  EXPECT_TRUE(m.on_frame(bad, kStart).empty());
  // The next (clean) frame queues behind the waiting one.
  EXPECT_TRUE(m.on_frame(good, kStart + 33 * kMs).empty());
  EXPECT_TRUE(m.release_due(kStart + 59 * kMs).empty());
  const std::vector<risk_t> out = m.release_due(kStart + 60 * kMs);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].seq, 100);
  EXPECT_EQ(out[0].cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(out[0].suspect, "a2");
  EXPECT_NE(out[0].detail.find("no motion estimate within 60 ms"), std::string::npos) << out[0].detail;
  EXPECT_EQ(out[1].seq, 101);
  EXPECT_EQ(out[1].level, risk_t::SAFE);
  EXPECT_EQ(m.estimate_stats().missing, 1);
  // The estimate arriving afterwards is late and changes nothing.
  EXPECT_TRUE(m.on_estimate(estimate_for(bad), kStart + 70 * kMs).empty());
  EXPECT_EQ(m.estimate_stats().late, 1);
}

TEST(EstimateWait, AnEstimateThatExplainsNothingNeverMakesTheFrameSafer) {
  for (const bool converged : {true, false}) {
    // No surfaces near the arm (they would make it an unknown object).
    discrepancy_t bad = summary_of(default_arm(16), 100);
    bad.near_arm_area_m2 = 0;
    motion_estimate_t e = estimate_for(bad);
    e.converged = converged;
    e.estimated_position[index_of(e, "a4")] += converged ? 0.0 : 20 * kDeg;
    RiskMonitor fresh(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
    feed_all(&fresh, kStart);
    fresh.on_estimate(e, kStart);  // already there when the frame comes
    const std::vector<risk_t> out = fresh.on_frame(bad, kStart);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].level, risk_t::WARNING);
    EXPECT_EQ(out[0].cause, risk_t::CAUSE_JOINT_ERROR);
    EXPECT_EQ(out[0].suspect, "a2");  // the discrepancy rules' suspect
    EXPECT_NE(out[0].detail.find("estimate explains nothing"), std::string::npos) << out[0].detail;
  }
}

TEST(EstimateWait, CleanFramesAndSensorFaultsDoNotWaitAndEstimatesCanBeSwitchedOff) {
  RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  feed_all(&m, kStart);
  const discrepancy_t good = summary_of(default_arm(), 101);
  ASSERT_EQ(m.on_frame(good, kStart).size(), 1u);
  discrepancy_t unusable = good;
  unusable.seq = good.seq + 1;  // the next frame (a repeated seq is refused)
  unusable.utime = good.utime + 33'000;
  unusable.usable = false;
  unusable.unusable_kind = discrepancy_t::UNUSABLE_RENDERER;
  unusable.unusable_reason = "renderer: joint a3 missing";
  const auto fault = m.on_frame(unusable, kStart);
  ASSERT_EQ(fault.size(), 1u);
  EXPECT_EQ(fault[0].cause, risk_t::CAUSE_SENSOR_FAULT);

  deployment::Config off = sim_config();
  off.risk.estimate_enabled = false;
  RiskMonitor without(off.risk, off.channels, friend_arm(), kRateHz, kStart);
  feed_all(&without, kStart);
  const auto out = without.on_frame(summary_of(default_arm(16), 100), kStart);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].suspect, "a2");
}

TEST(EstimateWait, EstimateVerdictsAreDebouncedLikeTheOthers) {
  RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  std::vector<int8_t> levels;
  for (int i = 0; i < 3; ++i) {
    const int64_t now = kStart + i * 33 * kMs;
    feed_all(&m, now);
    const discrepancy_t bad = summary_of(default_arm(16), 100 + i);
    EXPECT_TRUE(m.on_frame(bad, now).empty());
    motion_estimate_t e = estimate_for(bad);
    e.correction_translation[1] = 0.05;
    const auto out = m.on_estimate(e, now + 10 * kMs);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].cause, risk_t::CAUSE_CALIBRATION_ERROR);
    levels.push_back(out[0].level);
  }
  EXPECT_EQ(levels, (std::vector<int8_t>{risk_t::WARNING, risk_t::WARNING, risk_t::DANGEROUS}));
}

// ---- RiskMonitor: the arm leaving its plan ----

planned_trajectory_t plan_a1(int64_t from_utime, double from_rad, int64_t to_utime, double to_rad) {
  planned_trajectory_t p{};
  p.utime = from_utime;
  p.num_joints = 1;
  p.joint_name = {"a1"};
  p.num_points = 2;
  p.point_utime = {from_utime, to_utime};
  p.position = {{from_rad}, {to_rad}};
  return p;
}

// The verdict on one frame through the production path (on_frame): a frame
// without a model mismatch is judged on arrival, it never waits.
risk_t judged_at_once(RiskMonitor* m, const discrepancy_t& frame, int64_t now) {
  const std::vector<risk_t> verdicts = m->on_frame(frame, now);
  EXPECT_EQ(verdicts.size(), 1u) << "frame " << frame.seq << " should be judged on arrival";
  return verdicts.empty() ? risk_t{} : verdicts.front();
}

// Each frame is judged with the joint state of its capture time (the
// newest at or before its utime), whenever it is processed.
TEST(PlanDeviation, TheJointStateAtTheFramesUtimeAwayFromThePlanIsAFindingDebouncedLikeTheOthers) {
  RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  const int64_t t0 = 1'700'000'000'000'000;
  feed_all(&m, kStart);
  // a1 planned from 0 to 0.5 rad over 500 ms.
  m.on_plan(plan_a1(t0, 0.0, t0 + 500'000, 0.5));
  int64_t seq = 101;
  auto frame_at = [&](int64_t utime) {
    discrepancy_t d = summary_of(default_arm(), seq++);
    d.utime = utime;
    return d;
  };

  // On the plan at t0 + 200 ms (0.2 rad), within 5 deg.
  m.on_joint_state(joints_at(t0 + 200'000, 0.2 + 4.9 * kDeg), kStart);
  EXPECT_EQ(judged_at_once(&m, frame_at(t0 + 205'000), kStart).level, risk_t::SAFE);

  // 7.2 deg off from t0 + 210 ms on.
  std::vector<int8_t> levels;
  for (int i = 0; i < 3; ++i) {
    m.on_joint_state(joints_at(t0 + 210'000 + i * 10'000, 0.21 + i * 0.01 - 7.2 * kDeg), kStart);
    const risk_t r = judged_at_once(&m, frame_at(t0 + 215'000 + i * 10'000), kStart);
    EXPECT_EQ(r.cause, risk_t::CAUSE_UNCLASSIFIED);
    EXPECT_EQ(r.suspect, "a1");
    EXPECT_NEAR(r.score, 7.2, 1e-6);
    EXPECT_DOUBLE_EQ(r.threshold, 5.0);
    EXPECT_EQ(r.detail.rfind("arm left its plan (deg): a1 is 7.2° from the plan", 0), 0u) << r.detail;
    levels.push_back(r.level);
  }
  EXPECT_EQ(levels, (std::vector<int8_t>{risk_t::WARNING, risk_t::WARNING, risk_t::DANGEROUS}));

  // A frame captured before the deviation, judged late (after the deviating
  // joint states came): judged with the joint state of its own time.
  RiskMonitor late(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  feed_all(&late, kStart);
  late.on_plan(plan_a1(t0, 0.0, t0 + 500'000, 0.5));
  late.on_joint_state(joints_at(t0 + 200'000, 0.2), kStart);
  late.on_joint_state(joints_at(t0 + 300'000, 0.3 - 7.2 * kDeg), kStart);
  EXPECT_EQ(judged_at_once(&late, frame_at(t0 + 250'000), kStart).level, risk_t::SAFE);
  EXPECT_EQ(judged_at_once(&late, frame_at(t0 + 310'000), kStart).cause, risk_t::CAUSE_UNCLASSIFIED);

  // The stop's diagnosis stays open (DANGEROUS with the stop's finding)
  // until risk.evidence.clear_frames frames without a finding; the frames
  // below have none.
  // Beyond the plan's end there is nothing to compare with.
  m.on_joint_state(joints_at(t0 + 600'000, 3.0), kStart);
  risk_t open = judged_at_once(&m, frame_at(t0 + 605'000), kStart);
  EXPECT_EQ(open.level, risk_t::DANGEROUS);
  EXPECT_EQ(open.suspect, "a1");
  EXPECT_NE(open.detail.find("this frame: no finding"), std::string::npos) << open.detail;

  // A new plan replaces the old one from its first point on.
  m.on_plan(plan_a1(t0 + 550'000, 2.9, t0 + 900'000, 3.2));
  m.on_joint_state(joints_at(t0 + 610'000, 2.95), kStart);
  open = judged_at_once(&m, frame_at(t0 + 615'000), kStart);
  EXPECT_NE(open.detail.find("this frame: no finding"), std::string::npos) << open.detail;
  EXPECT_NE(open.detail.find("[clean 2/10 frames]"), std::string::npos) << open.detail;

  deployment::Config off = sim_config();
  off.risk.plan_enabled = false;
  RiskMonitor without(off.risk, off.channels, friend_arm(), kRateHz, kStart);
  feed_all(&without, kStart);
  without.on_plan(plan_a1(t0, 0.0, t0 + 500'000, 0.5));
  without.on_joint_state(joints_at(t0 + 200'000, 1.0), kStart);
  EXPECT_EQ(judged_at_once(&without, frame_at(t0 + 205'000), kStart).level, risk_t::SAFE);
}

// Each frame is classified once, on arrival, with the joint state of its
// capture time: a frame queued behind one that waits for its estimate keeps
// the finding it was classified with, whatever joint states arrive while it
// queues.
TEST(PlanDeviation, AQueuedFrameKeepsTheFindingItWasClassifiedWithOnArrival) {
  RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  const int64_t t0 = 1'700'000'000'000'000;
  feed_all(&m, kStart);
  m.on_plan(plan_a1(t0, 0.0, t0 + 500'000, 0.5));
  m.on_joint_state(joints_at(t0 + 200'000, 0.2 - 7.2 * kDeg), kStart);  // 7.2 deg off the plan
  const discrepancy_t waiting = mismatch_frame(100, 0);                 // waits up to 60 ms
  discrepancy_t queued = summary_of(default_arm(), 101);                // nothing the camera sees
  queued.utime = t0 + 243'000;
  EXPECT_TRUE(m.on_frame(waiting, kStart).empty());
  EXPECT_TRUE(m.on_frame(queued, kStart + 33 * kMs).empty());
  // Back on the plan before the queued frame's capture time, arriving while
  // it queues.
  m.on_joint_state(joints_at(t0 + 240'000, 0.24), kStart + 40 * kMs);
  const std::vector<risk_t> out = m.release_due(kStart + 60 * kMs);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].seq, 100);
  EXPECT_EQ(out[0].cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(out[1].seq, 101);
  EXPECT_EQ(out[1].cause, risk_t::CAUSE_UNCLASSIFIED);
  EXPECT_EQ(out[1].suspect, "a1");
  EXPECT_NEAR(out[1].score, 7.2, 1e-6);
  EXPECT_EQ(out[1].detail, "arm left its plan (deg): a1 is 7.2° from the plan (limit 5.0°) [2/3 frames]");
}

TEST(PlannedTrajectory, InterpolatesInsideItsSpanAndKeepsTheOldPlanBeforeANewOne) {
  PlannedTrajectory plan;
  EXPECT_FALSE(plan.at(5).has_value());
  plan.add(plan_a1(1000, 0.0, 2000, 1.0));
  EXPECT_DOUBLE_EQ(plan.at(1250)->at("a1"), 0.25);
  EXPECT_FALSE(plan.at(999).has_value());
  EXPECT_FALSE(plan.at(2001).has_value());
  plan.add(plan_a1(1500, 5.0, 2500, 6.0));
  EXPECT_DOUBLE_EQ(plan.at(1250)->at("a1"), 0.25);  // the old plan before 1500
  EXPECT_DOUBLE_EQ(plan.at(1500)->at("a1"), 5.0);   // the new one from 1500
  EXPECT_DOUBLE_EQ(plan.at(2000)->at("a1"), 5.5);
  EXPECT_EQ(plan.last_utime(), 2500);
}

// ---- Wire checks ----

TEST(WireChecks, MotionEstimate) {
  motion_estimate_t e = synthetic_estimate();
  EXPECT_EQ(check_motion_estimate(e), "");
  e.estimated_position[3] = NAN;
  EXPECT_EQ(check_motion_estimate(e), "estimated_position[3] (a4): expected a finite number, got nan");
  e = synthetic_estimate();
  e.correction_rotation[0] = 2;
  EXPECT_EQ(check_motion_estimate(e).rfind("correction_rotation: expected a unit quaternion", 0), 0u);
  e = synthetic_estimate();
  e.joint_name[2] = "a1";
  EXPECT_EQ(check_motion_estimate(e), "joint_name[2]: expected unique joint names, got 'a1' twice");
  e = synthetic_estimate();
  e.num_inliers = 2000;
  EXPECT_EQ(check_motion_estimate(e).rfind("num_inliers: expected 0..num_points = 1000", 0), 0u);
  e = synthetic_estimate();
  e.position_sigma[0] = -1;
  EXPECT_EQ(check_motion_estimate(e).rfind("position_sigma[0] (a1): expected a finite sigma >= 0", 0), 0u);
  e = synthetic_estimate();
  e.usable = false;
  EXPECT_EQ(check_motion_estimate(e),
            "unusable_reason: expected a reason for an unusable estimate, got an empty string");
  e.unusable_reason = "too few model points visible";
  e.correction_rotation[0] = 0;  // not looked at when unusable
  EXPECT_EQ(check_motion_estimate(e), "");
}

TEST(WireChecks, PlannedTrajectory) {
  planned_trajectory_t p = plan_a1(1000, 0.0, 2000, 1.0);
  EXPECT_EQ(check_planned_trajectory(p), "");
  p.point_utime[1] = 1000;
  EXPECT_EQ(check_planned_trajectory(p).rfind("point_utime[1]: expected strictly increasing times", 0), 0u);
  p = plan_a1(1000, 0.0, 2000, 1.0);
  p.position[1][0] = INFINITY;
  EXPECT_EQ(check_planned_trajectory(p), "position[1][0] (a1): expected a finite number, got inf");
  p = plan_a1(1000, 0.0, 2000, 1.0);
  p.num_points = 0;
  p.point_utime.clear();
  p.position.clear();
  EXPECT_EQ(check_planned_trajectory(p), "num_points: expected a count >= 1, got 0");
}

}  // namespace
}  // namespace tofguard::test
