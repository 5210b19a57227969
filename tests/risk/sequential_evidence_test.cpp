// The sequential evidence tests (risk/include/tofguard/risk/sequential_evidence.hpp)
// on synthetic evidence with known statistics: a parameter with information
// I has score s ~ N(0, I) without a fault and s ~ N(I * delta, I) with the
// parameter off by delta. Then the same evidence through RiskMonitor: the
// stop at once, the latched suspect and the diagnosis that stays open.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "synthetic_frames.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/risk/risk_monitor.hpp"
#include "tofguard/risk/sequential_evidence.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

using risk::EvidenceStep;
using risk::SequentialEvidence;

constexpr double kDeg = M_PI / 180.0;
constexpr double kRateHz = 30;  // camera.rate_hz of config/sim.yaml

const deployment::Config& sim_config() {
  static const deployment::Config config =
      deployment::load_config(source_dir() + "/config/sim.yaml", nullptr);
  return config;
}

const robot_model::KinematicTree& friend_arm() {
  static const robot_model::KinematicTree tree =
      robot_model::load_kinematic_tree(sim_config().robot.urdf_path);
  return tree;
}

const std::vector<std::string> kJoints = {"a1", "a2", "a3", "a4", "a5", "a6", "a7"};

// Information per joint (1/rad^2), from well seen (a1: a 3 degree offset is
// 52 sigma in one frame) to hardly seen (a7: 0.03 sigma).
const std::map<std::string, double> kJointInformation = {{"a1", 1e6}, {"a2", 1e5}, {"a3", 1e4}, {"a4", 3e3},
                                                         {"a5", 1e3}, {"a6", 1e2}, {"a7", 1.0}};
// Camera information per image region (discrepancy_t.camera_region_*),
// diagonal: translation 1/m^2, rotation 1/rad^2. The whole image has four
// times as much.
const std::array<double, 6> kCameraInformation = {3e5, 3e4, 1e3, 1e4, 1e3, 10};

// A usable frame whose evidence fields hold the given scores (all zero by
// default) and kJointInformation / kCameraInformation.
discrepancy_t evidence_frame(int64_t seq) {
  discrepancy_t d{};
  d.utime = 1'700'000'000'000'000 + seq * 33'333;
  d.seq = seq;
  d.camera_id = sim_config().camera.id;
  d.usable = true;
  d.calibrated = true;
  d.width = 176;
  d.height = 144;
  d.num_pixels = d.width * d.height;
  d.num_match = d.num_pixels;
  d.num_compared = d.num_pixels;
  d.evidence_available = true;
  for (int a = 0; a < 6; ++a) {
    d.camera_information[a * 6 + a] = 4 * kCameraInformation[a];
    for (int r = 0; r < 4; ++r) d.camera_region_information[6 * r + a] = kCameraInformation[a];
  }
  d.camera_fit_pixels = 4000;
  std::fill(d.camera_region_fit_pixels, d.camera_region_fit_pixels + 4, 1000);
  d.num_joints = static_cast<int>(kJoints.size());
  for (const std::string& j : kJoints) {
    d.joint_name.push_back(j);
    d.joint_fit_pixels.push_back(300);
    d.joint_score.push_back(0);
    d.joint_information.push_back(kJointInformation.at(j));
    d.joint_naming_score.push_back(0);
    d.joint_naming_information.push_back(kJointInformation.at(j));
  }
  return d;
}

// The naming search's fields on `d` (2000 points searched), every joint's
// offset and gain 0: a test sets the gains it needs.
void add_search(discrepancy_t* d) {
  d->search_points = 2000;
  d->joint_search_offset.assign(d->num_joints, 0.0);
  d->joint_search_gain.assign(d->num_joints, 0.0);
}

int joint_index(const std::string& joint) {
  return static_cast<int>(std::find(kJoints.begin(), kJoints.end(), joint) - kJoints.begin());
}

// Scores drawn for one frame: every parameter N(I * offset, I), with the
// offsets given (radians; camera metres / radians), all others 0.
class ScoreSource {
 public:
  explicit ScoreSource(uint32_t seed) : random_(seed) {}
  // camera_offset: the pose error, seen in every region; region_offset
  // (when given) replaces it in region `region` alone (an object flush with
  // a modelled surface there).
  discrepancy_t frame(int64_t seq, const std::map<std::string, double>& joint_offsets = {},
                      const std::array<double, 6>& camera_offset = {}, int region = -1,
                      const std::array<double, 6>& region_offset = {}) {
    discrepancy_t d = evidence_frame(seq);
    for (int i = 0; i < d.num_joints; ++i) {
      const double information = d.joint_information[i];
      const auto offset = joint_offsets.find(d.joint_name[i]);
      const double delta = offset == joint_offsets.end() ? 0 : offset->second;
      d.joint_score[i] = information * delta + std::sqrt(information) * normal_(random_);
    }
    d.joint_naming_score = d.joint_score;
    for (int r = 0; r < 4; ++r) {
      const std::array<double, 6>& offset = r == region ? region_offset : camera_offset;
      for (int a = 0; a < 6; ++a) {
        const double information = kCameraInformation[a];
        const double score = information * offset[a] + std::sqrt(information) * normal_(random_);
        d.camera_region_score[6 * r + a] = score;
        d.camera_score[a] += score;
      }
    }
    return d;
  }

 private:
  std::mt19937_64 random_;
  std::normal_distribution<double> normal_;
};

TEST(EvidenceTests, LogCoshIsExactAndNeverOverflows) {
  for (double x : {0.0, 1e-8, 0.3, -1.7, 5.0, 20.0})
    EXPECT_NEAR(risk::log_cosh(x), std::log(std::cosh(x)), 1e-12);
  EXPECT_NEAR(risk::log_cosh(1e6), 1e6 - std::log(2.0), 1e-6);
  EXPECT_NEAR(risk::log_cosh(-1e6), 1e6 - std::log(2.0), 1e-6);
  // No information, no score: the alternative and the null agree.
  EXPECT_DOUBLE_EQ(risk::joint_llr(0, 0, 3 * kDeg), 0);
  EXPECT_DOUBLE_EQ(risk::camera_llr({}, {}, {0.02, 0.02, 0.02, kDeg, kDeg, kDeg}), 0);
}

TEST(EvidenceTests, TheThresholdFollowsFromTheFalseStopRate) {
  // docs/safety-chain.md: h = ln(K * rate * 3600 s/h * period).
  EXPECT_NEAR(risk::cusum_threshold(8, 30, 1000), std::log(8 * 30 * 3600.0 * 1000), 1e-12);
  EXPECT_NEAR(risk::cusum_threshold(8, 30, 1000), 20.577, 1e-3);
  const SequentialEvidence evidence(sim_config().risk, friend_arm(), sim_config().camera.rate_hz);
  // The camera's test and two for each of a1..a7 (at joint_offset and at
  // large_joint_offset).
  EXPECT_EQ(evidence.hypotheses(), 15);
  EXPECT_NEAR(evidence.threshold(), 21.206, 1e-3);
  EXPECT_NEAR(evidence.warning_level(), 0.5 * 21.206, 1e-3);
}

// 200 000 nominal frames (1.85 hours at 30 Hz): no test crosses h, and
// every per-frame log-likelihood ratio has a negative mean (the CUSUMs
// drift down to 0).
TEST(EvidenceTests, NominalFramesNeverCrossAndEveryRatioDriftsDown) {
  const risk::RiskSettings& settings = sim_config().risk;
  SequentialEvidence evidence(settings, friend_arm(), kRateHz);
  ScoreSource source(14);
  const std::array<double, 6> camera_delta = {0.02, 0.02, 0.02, kDeg, kDeg, kDeg};
  std::map<std::string, double> llr_sum;
  double camera_llr_sum = 0;
  std::map<std::string, double> largest;
  double camera_largest = 0;
  constexpr int kFrames = 200000;
  for (int k = 0; k < kFrames; ++k) {
    const discrepancy_t d = source.frame(k);
    const EvidenceStep step = evidence.update(d);
    ASSERT_FALSE(step.crossed) << "frame " << k << ": " << step.finding.detail;
    for (int i = 0; i < d.num_joints; ++i) {
      llr_sum[d.joint_name[i]] += risk::joint_llr(d.joint_score[i], d.joint_information[i], 3 * kDeg);
      largest[d.joint_name[i]] = std::max(largest[d.joint_name[i]], evidence.joint_cusum(d.joint_name[i]));
    }
    const risk::CameraRegionRatio camera = risk::camera_region_llr(d, camera_delta);
    ASSERT_EQ(camera.voters, 4);
    ASSERT_EQ(camera.agree, 3);
    camera_llr_sum += camera.llr;
    camera_largest = std::max(camera_largest, evidence.camera_cusum());
  }
  for (const auto& [joint, sum] : llr_sum) {
    EXPECT_LT(sum / kFrames, 0) << joint;
    EXPECT_LT(largest[joint], evidence.threshold()) << joint;
    std::cout << joint << ": mean LLR " << sum / kFrames << ", largest CUSUM " << largest[joint] << "\n";
  }
  EXPECT_LT(camera_llr_sum / kFrames, 0);
  std::cout << "camera: mean LLR " << camera_llr_sum / kFrames << ", largest CUSUM " << camera_largest
            << ", h " << evidence.threshold() << "\n";
}

TEST(EvidenceTests, AGrossFaultCrossesOnItsFirstFrame) {
  SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
  ScoreSource source(3);
  // a1 (I = 1e6 / rad^2) off by 3 degrees: 2742 in delta^2 I, drift 1371 per frame.
  const EvidenceStep step = evidence.update(source.frame(1, {{"a1", 3 * kDeg}}));
  ASSERT_TRUE(step.crossed);
  EXPECT_EQ(step.finding.cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(step.finding.suspect, "a1");
  EXPECT_DOUBLE_EQ(step.finding.threshold, evidence.threshold());
  EXPECT_NE(step.finding.detail.find("fitted offset (seen - reported) "), std::string::npos)
      << step.finding.detail;
  EXPECT_NE(step.finding.detail.find("° ± 0.1°"), std::string::npos) << step.finding.detail;

  // The camera 2 cm off sideways (x, I = 3e5 / m^2 per region: 120 in
  // delta^2 I, each of the four regions alone crosses h) at once.
  SequentialEvidence camera(sim_config().risk, friend_arm(), kRateHz);
  const EvidenceStep moved = camera.update(source.frame(1, {}, {0.02, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(moved.crossed);
  EXPECT_EQ(moved.finding.cause, risk_t::CAUSE_CALIBRATION_ERROR);
  EXPECT_EQ(moved.finding.suspect, "");
}

// An object flush with a modelled surface (within the naming gate) pulls
// the camera fit of the region it is in: the pose error that explains it
// there is gross (here 3 cm sideways, 270 in delta^2 I), but the other
// regions see none. Three regions must agree: 20 000 such frames never
// cross, while the same error in every region crosses at once.
TEST(EvidenceTests, ACameraErrorInOneRegionAloneIsNotAPoseError) {
  const std::array<double, 6> shifted = {0.03, 0, 0, 0, 0, 0};
  ScoreSource source(21);
  for (int region = 0; region < 4; ++region) {
    SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
    double largest = 0;
    for (int k = 0; k < 5000; ++k) {
      const EvidenceStep step = evidence.update(source.frame(k, {}, {}, region, shifted));
      ASSERT_FALSE(step.crossed) << "region " << region << ", frame " << k << ": " << step.finding.detail;
      largest = std::max(largest, evidence.camera_cusum());
    }
    std::cout << "3 cm in region " << region << " alone: largest camera CUSUM " << largest << " of h "
              << evidence.threshold() << "\n";
  }
  // Two regions with a pose error and two without: still not three.
  discrepancy_t two = source.frame(1, {}, shifted, 0, {});
  std::fill(two.camera_region_score, two.camera_region_score + 6, 0.0);
  std::fill(two.camera_region_score + 6, two.camera_region_score + 12, 0.0);
  SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
  EXPECT_FALSE(evidence.update(two).crossed);
  EXPECT_EQ(risk::camera_region_llr(two, {0.02, 0.02, 0.02, kDeg, kDeg, kDeg}).agree, 3);
  SequentialEvidence whole(sim_config().risk, friend_arm(), kRateHz);
  const EvidenceStep step = whole.update(source.frame(1, {}, shifted));
  ASSERT_TRUE(step.crossed);
  EXPECT_EQ(step.finding.cause, risk_t::CAUSE_CALIBRATION_ERROR);
}

// Regions that cannot carry a nat at delta do not vote (a region of sky or
// of the arm alone): with two such, the other two must both agree; with
// none voting (a frame without regions), the whole image decides.
TEST(EvidenceTests, RegionsWithoutEvidenceDoNotVote) {
  const std::array<double, 6> delta = {0.02, 0.02, 0.02, kDeg, kDeg, kDeg};
  const std::array<double, 6> shifted = {0.02, 0, 0, 0, 0, 0};
  ScoreSource source(22);
  discrepancy_t d = source.frame(1, {}, shifted);
  for (int r : {1, 3}) {
    std::fill(d.camera_region_information + 6 * r, d.camera_region_information + 6 * r + 6, 0.0);
    std::fill(d.camera_region_score + 6 * r, d.camera_region_score + 6 * r + 6, 0.0);
  }
  // 1 nat at delta: 2 cm with I = 5000 / m^2 is delta^2 I / 2 = 1.
  EXPECT_TRUE(risk::camera_region_votes(&d.camera_region_information[0], delta));
  const std::array<double, 6> one_nat = {5000, 0, 0, 0, 0, 0};
  const std::array<double, 6> below = {4999, 0, 0, 0, 0, 0};
  EXPECT_TRUE(risk::camera_region_votes(one_nat.data(), delta));
  EXPECT_FALSE(risk::camera_region_votes(below.data(), delta));
  risk::CameraRegionRatio ratio = risk::camera_region_llr(d, delta);
  EXPECT_EQ(ratio.voters, 2);
  EXPECT_EQ(ratio.agree, 2);
  SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
  EXPECT_TRUE(evidence.update(d).crossed);
  // One of the two without the error: no.
  std::fill(d.camera_region_score, d.camera_region_score + 6, 0.0);
  SequentialEvidence other(sim_config().risk, friend_arm(), kRateHz);
  EXPECT_FALSE(other.update(d).crossed);
  // No regions at all: the whole image's ratio.
  discrepancy_t whole = source.frame(2, {}, shifted);
  std::fill(whole.camera_region_information, whole.camera_region_information + 24, 0.0);
  ratio = risk::camera_region_llr(whole, delta);
  EXPECT_EQ(ratio.voters, 0);
  std::array<double, 6> score;
  std::array<double, 36> information;
  std::copy(whole.camera_score, whole.camera_score + 6, score.begin());
  std::copy(whole.camera_information, whole.camera_information + 36, information.begin());
  EXPECT_DOUBLE_EQ(ratio.llr, risk::camera_llr(score, information, delta));
}

// A marginal fault accumulates: a4 (I = 3e3 / rad^2) off by 3 degrees is
// 2.9 in delta^2 I per frame, so it crosses after about h / (delta^2 I / 2)
// frames (the mixture over both signs costs up to log 2 per frame more).
TEST(EvidenceTests, AMarginalFaultCrossesAfterSeveralFramesAsDerived) {
  const double delta = 3 * kDeg;
  const double drift = delta * delta * kJointInformation.at("a4") / 2;
  ScoreSource source(5);
  double frames_sum = 0;
  constexpr int kTrials = 200;
  double h = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
    h = evidence.threshold();
    int frames = 0;
    EvidenceStep step;
    while (!step.crossed) {
      step = evidence.update(source.frame(frames, {{"a4", delta}}));
      ++frames;
      ASSERT_LT(frames, 1000);
    }
    EXPECT_EQ(step.finding.suspect, "a4");
    frames_sum += frames;
  }
  const double mean = frames_sum / kTrials;
  const double derived = h / drift;
  std::cout << "a4 off by 3 deg, delta^2 I = " << 2 * drift << ": crossed after " << mean
            << " frames, h / (delta^2 I / 2) = " << derived << "\n";
  EXPECT_GT(mean, 3);
  EXPECT_GE(mean, 0.8 * derived);
  EXPECT_LE(mean, 2.0 * derived);
}

// Two cameras that each see a5 as well (I = 1000 per frame) and a 3 degree
// offset of it: the joints' tests pooled over both cameras' frames (60
// frames a second) cross sooner than the first of the cameras' own tests
// (in about half the time one camera's need), as derived: h / (E[ratio] - decay) frames at the pooled rate,
// with E[ratio] the per-frame log-likelihood ratio's mean under the fault.
TEST(EvidenceTests, PooledOverTwoCamerasAFaultBothSeeCrossesSoonerThanEitherCamerasOwnTests) {
  const double delta = 3 * kDeg;
  const risk::RiskSettings each = risk::several_cameras_evidence_settings(sim_config().risk, 2);
  EXPECT_EQ(each.evidence_false_stop_period_h, 3 * sim_config().risk.evidence_false_stop_period_h);
  ScoreSource mast(11);
  ScoreSource side(12);
  constexpr int kTrials = 40;
  double own_s = 0;
  double pooled_s = 0;
  double pooled_h = 0;
  double pooled_decay = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    SequentialEvidence mast_tests(each, friend_arm(), kRateHz);
    SequentialEvidence side_tests(each, friend_arm(), kRateHz);
    SequentialEvidence pooled(each, friend_arm(), 2 * kRateHz, /*camera_test=*/false);
    pooled_h = pooled.threshold();
    pooled_decay = pooled.memory_decay();
    EXPECT_EQ(pooled.hypotheses(), 14);
    EXPECT_NEAR(pooled_h, risk::cusum_threshold(14, 2 * kRateHz, each.evidence_false_stop_period_h), 1e-12);
    int own_frames = -1;
    int pooled_frames = -1;
    for (int k = 0; k < 2000 && (own_frames < 0 || pooled_frames < 0); ++k) {
      // One frame of each camera per camera period, the pooled tests
      // taking both.
      const discrepancy_t m = mast.frame(k, {{"a5", delta}});
      const discrepancy_t d = side.frame(k, {{"a5", delta}});
      const bool mast_crossed = mast_tests.update(m).crossed;
      const bool side_crossed = side_tests.update(d).crossed;
      const bool own = mast_crossed || side_crossed;
      const bool pooled_after_mast = pooled.update(m).crossed;
      const bool pooled_after_side = pooled.update(d).crossed;
      const bool pooled_crossed = pooled_after_mast || pooled_after_side;
      if (own && own_frames < 0) own_frames = k + 1;
      if (pooled_crossed && pooled_frames < 0) pooled_frames = k + 1;
    }
    ASSERT_GT(own_frames, 0);
    ASSERT_GT(pooled_frames, 0);
    own_s += own_frames / kRateHz;
    pooled_s += pooled_frames / kRateHz;
  }
  own_s /= kTrials;
  pooled_s /= kTrials;
  // E[ratio]: the test at joint_offset (3 degrees) under the fault, by
  // Monte Carlo.
  const double information = kJointInformation.at("a5");
  std::mt19937_64 random(3);
  std::normal_distribution<double> normal;
  double mean_ratio = 0;
  constexpr int kDraws = 200000;
  for (int n = 0; n < kDraws; ++n) {
    const double score = information * delta + std::sqrt(information) * normal(random);
    mean_ratio += risk::joint_llr(score, information, delta) / kDraws;
  }
  const double derived_s = pooled_h / (mean_ratio - pooled_decay) / (2 * kRateHz);
  std::cout << "a5 off by 3 deg seen by two cameras: the first camera's own test crossed after " << own_s
            << " s, the pooled tests after " << pooled_s << " s (derived " << derived_s << " s)\n";
  EXPECT_LT(pooled_s, 0.7 * own_s);
  EXPECT_GE(pooled_s, 0.7 * derived_s);
  EXPECT_LE(pooled_s, 1.5 * derived_s);
}

// Two joints' tests crossed: the suspect is the one whose one-parameter
// naming fit explains this frame's residual best (the largest s^2 / I).
TEST(EvidenceTests, TheSuspectIsTheJointWhoseNamingFitExplainsMost) {
  SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
  discrepancy_t d = evidence_frame(1);
  d.joint_score[joint_index("a2")] = 1e5 * 4 * kDeg;  // s^2 / I = 1e5 * (4 deg)^2 = 487
  d.joint_score[joint_index("a3")] = 1e4 * 6 * kDeg;  // 1e4 * (6 deg)^2 = 110
  d.joint_naming_score = d.joint_score;
  EvidenceStep step = evidence.update(d);
  ASSERT_TRUE(step.crossed);
  EXPECT_GE(evidence.joint_cusum("a3"), evidence.threshold());
  EXPECT_EQ(step.finding.suspect, "a2");
  d.joint_score[joint_index("a3")] = 1e4 * 15 * kDeg;  // 685
  d.joint_naming_score = d.joint_score;
  step = evidence.update(d);
  EXPECT_EQ(step.finding.suspect, "a3");
  // Only a4's CUSUM crossed, but a3's naming fit explains the frame best
  // (a joint's offset moves the distal links most, where J is least
  // linear): a3 is named.
  SequentialEvidence other(sim_config().risk, friend_arm(), kRateHz);
  d = evidence_frame(1);
  d.joint_score[joint_index("a4")] = 1e5 * 6 * kDeg;
  d.joint_naming_score[joint_index("a4")] = 3e3 * 1 * kDeg;  // s^2 / I = 3e3 * (1 deg)^2 = 0.9
  d.joint_naming_score[joint_index("a3")] = 1e4 * 4 * kDeg;  // 49
  step = other.update(d);
  ASSERT_TRUE(step.crossed);
  EXPECT_LT(other.joint_cusum("a3"), other.threshold());
  EXPECT_EQ(step.finding.suspect, "a3");
}

// A frame with the naming search (discrepancy_t.joint_search_*): the
// suspect is the joint whose searched offset explains most, whatever the
// linear naming fit says (out of its range it may prefer a neighbour), and
// the detail gives the searched offset.
TEST(EvidenceTests, TheNamingSearchOutranksTheLinearNamingFit) {
  SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
  discrepancy_t d = evidence_frame(1);
  d.joint_score[joint_index("a3")] = 1e5 * 6 * kDeg;  // a3's test crosses
  d.joint_naming_score = d.joint_score;               // and its linear fit explains most
  add_search(&d);
  d.joint_search_offset[joint_index("a2")] = -10 * kDeg;
  d.joint_search_gain[joint_index("a2")] = 9000;
  d.joint_search_offset[joint_index("a3")] = 4 * kDeg;
  d.joint_search_gain[joint_index("a3")] = 2000;
  EvidenceStep step = evidence.update(d);
  ASSERT_TRUE(step.crossed);
  EXPECT_EQ(step.finding.cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(step.finding.suspect, "a2");
  EXPECT_NE(step.finding.detail.find("named by the search: -10.0°"), std::string::npos)
      << step.finding.detail;
  EXPECT_NE(step.finding.detail.find("the test that crossed: a3's"), std::string::npos)
      << step.finding.detail;
  // A joint whose test has not crossed must explain the frame better than
  // the crossed one by 2h (this frame alone preferring it at the
  // threshold's level): a2 by 1.5h does not, by 2.5h it does.
  SequentialEvidence other(sim_config().risk, friend_arm(), kRateHz);
  const double h = other.threshold();
  d.joint_search_gain[joint_index("a2")] = 3.5 * h;
  d.joint_search_gain[joint_index("a3")] = 2.0 * h;
  step = other.update(d);
  EXPECT_EQ(step.finding.suspect, "a3");
  SequentialEvidence third(sim_config().risk, friend_arm(), kRateHz);
  d.joint_search_gain[joint_index("a2")] = 4.5 * h;
  step = third.update(d);
  EXPECT_EQ(step.finding.suspect, "a2");
  // The crossed joint explains nothing this frame: a non-crossed one still
  // needs 2h against nothing; below that, the crossed a3 is named.
  SequentialEvidence fourth(sim_config().risk, friend_arm(), kRateHz);
  d.joint_search_gain[joint_index("a2")] = 1.5 * h;
  d.joint_search_gain[joint_index("a3")] = 0;
  step = fourth.update(d);
  ASSERT_TRUE(step.crossed);
  EXPECT_EQ(step.finding.suspect, "a3");
}

// The naming search's camera candidate: a joint's test crossed, and a camera
// move explains the frame 2h better than any joint's offset (a camera
// shifted sideways moves the arm as a1 turns it): a calibration error,
// with the joint's test as the one that crossed; by less, the joint.
TEST(EvidenceTests, ACameraMoveTheSearchPrefersBy2hIsACalibrationError) {
  discrepancy_t d = evidence_frame(1);
  d.joint_score[joint_index("a1")] = 1e6 * 3 * kDeg;  // a1's test crosses
  d.joint_naming_score = d.joint_score;
  add_search(&d);
  d.joint_search_offset[joint_index("a1")] = 5.5 * kDeg;
  d.joint_search_gain[joint_index("a1")] = 4000;
  d.camera_search_static_points = 2500;
  d.camera_search_axis = 0;
  d.camera_search_offset = 0.02;
  SequentialEvidence below(sim_config().risk, friend_arm(), kRateHz);
  const double h = below.threshold();
  d.camera_search_gain = 4000 + 1.5 * h;
  EvidenceStep step = below.update(d);
  ASSERT_TRUE(step.crossed);
  EXPECT_EQ(step.finding.cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(step.finding.suspect, "a1");
  SequentialEvidence beyond(sim_config().risk, friend_arm(), kRateHz);
  d.camera_search_gain = 4000 + 2.5 * h;
  step = beyond.update(d);
  ASSERT_TRUE(step.crossed);
  EXPECT_EQ(step.finding.cause, risk_t::CAUSE_CALIBRATION_ERROR);
  EXPECT_EQ(step.finding.crossed_test, "a1");
  EXPECT_NE(step.finding.detail.find("the camera moved 2.0 cm along optical x"), std::string::npos)
      << step.finding.detail;
  EXPECT_NE(step.finding.detail.find("the test that crossed: a1's"), std::string::npos)
      << step.finding.detail;
  // No camera candidate (axis -1): the joint, however large the gain field.
  SequentialEvidence none(sim_config().risk, friend_arm(), kRateHz);
  d.camera_search_axis = -1;
  step = none.update(d);
  EXPECT_EQ(step.finding.cause, risk_t::CAUSE_JOINT_ERROR);
}

// A joint's test crossed but no joint is in this frame's naming fit (every
// robot pixel beyond the gate: a gross offset): still a stop, blaming the
// joint whose test crossed.
TEST(EvidenceTests, ACrossedTestStopsWhenNoJointIsInTheNamingFit) {
  SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
  discrepancy_t d = evidence_frame(1);
  d.joint_score[joint_index("a2")] = 1e5 * 20 * kDeg;
  d.joint_naming_information.assign(d.num_joints, 0.0);
  const EvidenceStep step = evidence.update(d);
  ASSERT_TRUE(step.crossed);
  EXPECT_EQ(step.finding.cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(step.finding.suspect, "a2");
  EXPECT_GE(step.finding.score, evidence.threshold());
}

TEST(EvidenceTests, GrowingEvidenceWarnsBeforeItCrosses) {
  SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
  discrepancy_t d = evidence_frame(1);
  // a5 (I = 1e3): s = I * 6 deg gives LLR = log cosh(104.7 * 0.0524) - 1.37 = 3.4 per frame.
  d.joint_score[joint_index("a5")] = 1e3 * 6 * kDeg;
  int warnings = 0;
  EvidenceStep step;
  for (int k = 0; k < 10 && !step.crossed; ++k) {
    step = evidence.update(d);
    if (step.warning) {
      ++warnings;
      EXPECT_EQ(step.finding.suspect, "a5");
      EXPECT_GE(evidence.joint_cusum("a5"), evidence.warning_level());
      EXPECT_FALSE(step.quiet);
    }
  }
  EXPECT_TRUE(step.crossed);
  EXPECT_GE(warnings, 2);
  evidence.reset();
  EXPECT_TRUE(evidence.quiet());
  EXPECT_DOUBLE_EQ(evidence.joint_cusum("a5"), 0);
}

// A hardly informed test (a7: I = 1 / rad^2, delta^2 I = 0.003 per frame;
// the large-offset test's 0.03) raised by one outlying frame keeps it without the memory decay: the
// mixture's drift without a fault is -(delta^2 I)^2 / 4 = -2e-6 per frame,
// 20 000 hours from the warning level back to 0. With it the CUSUM falls by
// h / (rate * kEvidenceMemoryS) = 0.011 per frame: below the warning level
// within about 400 frames, and to 0 within the memory's 1800 frames.
TEST(EvidenceTests, AHardlyInformedTestForgetsWithinItsMemory) {
  SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
  EXPECT_NEAR(evidence.memory_decay(), evidence.threshold() / (kRateHz * risk::kEvidenceMemoryS), 1e-12);
  ScoreSource source(8);
  discrepancy_t outlier = source.frame(1);
  // 100 sigma in one frame: the large-offset test's LLR = log cosh(0.1745 * 100)
  // - ... = 16.8 (the first test's 4.5).
  outlier.joint_score[joint_index("a7")] = 100;
  evidence.update(outlier);
  const double raised = evidence.joint_cusum("a7");
  ASSERT_GT(raised, evidence.warning_level());
  ASSERT_LT(raised, evidence.threshold());
  const double expected_frames = (raised - evidence.warning_level()) / evidence.memory_decay();
  int frames = 0;
  while (!evidence.quiet()) {
    ASSERT_LT(frames, 1.05 * expected_frames) << "a7 at " << evidence.joint_cusum("a7");
    evidence.update(source.frame(2 + frames));
    ++frames;
  }
  EXPECT_GE(frames, 0.95 * expected_frames);
  while (evidence.joint_cusum("a7") > 0) {
    ASSERT_LT(frames, kRateHz * risk::kEvidenceMemoryS) << "a7 at " << evidence.joint_cusum("a7");
    evidence.update(source.frame(2 + frames));
    ++frames;
  }
  std::cout << "a7 raised to " << raised << " of h " << evidence.threshold() << ": below the warning level "
            << expected_frames << " frames later (derived), at 0 after " << frames << " frames\n";
}

// The smallest offset a frame can show (smallest_growing_offset): on
// shrunk scores of a joint off by theta, s ~ N(theta I, I) less the static
// bound B, the stop test's mean ratio less the memory decay is below 0 at
// 0.8 of it and above 0 at 1.5 of it, for a hardly seen joint with a wide
// allowance (the default arm's a7 on a commissioned camera: 1.4 deg per
// frame, B / I = 2.3 deg), a well seen one with a narrow allowance, and
// one without an allowance (where it is delta / 2 plus the decay's share).
TEST(EvidenceTests, TheSmallestOffsetAFrameCanShowIsWhereTheRatioTurns) {
  const double delta = 3 * kDeg;
  const double decay = 20.6 / (kRateHz * risk::kEvidenceMemoryS);
  struct Case {
    double sigma_deg, bound_deg, expected_deg;
  };
  // Expected: B/I + d'/2 + decay / (d' I), d' = 3 deg - B/I.
  for (const Case& c : {Case{1.4, 2.3, 2.68}, Case{0.3, 1.0, 2.00}, Case{1.0, 0.0, 1.50}}) {
    const double information = 1 / std::pow(c.sigma_deg * kDeg, 2);
    const double bound = c.bound_deg * kDeg * information;
    const double smallest = risk::smallest_growing_offset(delta, information, bound, decay);
    EXPECT_NEAR(smallest / kDeg, c.expected_deg, 0.01) << c.sigma_deg << " deg per frame";
    const double tested = risk::effective_delta(delta, information, bound);
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0, std::sqrt(information));
    for (const double fraction : {0.8, 1.5}) {
      double sum = 0;
      constexpr int kFrames = 50000;
      for (int k = 0; k < kFrames; ++k) {
        const double s = fraction * smallest * information + noise(rng);
        const double shrunk = std::copysign(std::max(0.0, std::abs(s) - bound), s);
        sum += risk::joint_llr(shrunk, information, tested) - decay;
      }
      const double mean = sum / kFrames;
      if (fraction < 1) {
        EXPECT_LT(mean, 0) << fraction << " of " << smallest / kDeg << " deg";
      } else {
        EXPECT_GT(mean, 0) << fraction << " of " << smallest / kDeg << " deg";
      }
    }
  }
  // The allowance covers the whole alternative: no offset shows.
  const double information = 1 / std::pow(1.4 * kDeg, 2);
  EXPECT_TRUE(std::isinf(risk::smallest_growing_offset(delta, information, 3.1 * kDeg * information, decay)));
  EXPECT_TRUE(std::isinf(risk::smallest_growing_offset(delta, 0, 0, decay)));
}

// A joint whose static allowance covers the first test's whole alternative
// (B / I = 4 deg > delta = 3 deg: that test gains nothing) is still
// guarded by its large-offset test (10 deg, tested at 10 - 4 = 6 deg): the
// default arm's wrist on a commissioned camera. Nominal frames with a bias
// at the bound never cross; a 20 deg offset that the linear fit reads as
// 16 deg crosses on its first frame, named as the large-offset test's; with the
// offset gone, the clearing test at half the large-offset test's alternative
// clears within a few frames.
TEST(EvidenceTests, ALargeOffsetShowsWhereTheAllowanceCoversTheFirstTest) {
  SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
  const int a6 = joint_index("a6");
  const double information = 1 / std::pow(0.8 * kDeg, 2);
  const double bound = 4 * kDeg * information;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, std::sqrt(information));
  int64_t seq = 1;
  // The frame's shrunk score of a6 off by read_deg (as the fit reads it)
  // with a static bias of `bias` (score units) and noise.
  const auto frame = [&](double read_deg, double bias) {
    discrepancy_t d = evidence_frame(seq++);
    d.joint_information[a6] = information;
    d.joint_static_bound.assign(d.num_joints, 0.0);
    d.joint_static_bound[a6] = bound;
    const double s = read_deg * kDeg * information + bias + noise(rng);
    d.joint_score[a6] = std::copysign(std::max(0.0, std::abs(s) - bound), s);
    d.joint_naming_score = d.joint_score;
    return d;
  };
  ASSERT_TRUE(
      std::isinf(risk::smallest_growing_offset(3 * kDeg, information, bound, evidence.memory_decay())));
  double smallest = evidence.smallest_offset(frame(0, 0), a6) / kDeg;
  EXPECT_GT(smallest, 7.0);  // B/I + 6/2 + decay's share
  EXPECT_LT(smallest, 7.1);
  double largest = 0;
  for (int k = 0; k < 3000; ++k) {
    const EvidenceStep step = evidence.update(frame(0, (k % 2 == 0 ? 1 : -1) * bound));
    ASSERT_FALSE(step.crossed) << "frame " << k << ": " << step.finding.detail;
    largest = std::max(largest, evidence.joint_cusum("a6"));
  }
  EXPECT_LT(largest, evidence.warning_level());
  const EvidenceStep step = evidence.update(frame(-16, 0));
  ASSERT_TRUE(step.crossed);
  EXPECT_EQ(step.finding.suspect, "a6");
  EXPECT_GE(evidence.joint_large_cusum("a6"), evidence.threshold());
  EXPECT_NE(step.finding.detail.find("its test at the large offset 10°"), std::string::npos)
      << step.finding.detail;
  EXPECT_FALSE(evidence.cleared("a6"));
  int frames_to_clear = 0;
  while (!evidence.cleared("a6")) {
    ASSERT_LT(frames_to_clear, 20) << evidence.clearing_summary("a6");
    evidence.update(frame(0, 0));
    ++frames_to_clear;
  }
  EXPECT_GE(frames_to_clear, 2);
}

// A fault that the fit reads smaller than half the test's delta (a large
// offset outside the fit's linear range, as the arm moves) turns the stop
// test against it, so its CUSUM falls below the warning level; the
// clearing test, at delta/2, still sees it, and only a fault gone clears.
TEST(EvidenceTests, OnlyEvidenceThatTheFaultIsGoneClearsACrossedTest) {
  SequentialEvidence evidence(sim_config().risk, friend_arm(), kRateHz);
  ScoreSource source(21);
  int64_t seq = 1;
  // a3 (I = 1e4, delta 3 deg: 5.2 sigma per frame) 6 deg off: crosses at once.
  EvidenceStep step = evidence.update(source.frame(seq++, {{"a3", 6 * kDeg}}));
  ASSERT_TRUE(step.crossed);
  EXPECT_FALSE(evidence.cleared("a3"));
  EXPECT_TRUE(evidence.cleared("no such joint"));
  // Read as 1.2 deg (0.4 delta) for 300 frames: the stop test's drift is
  // delta I (0.4 - 0.5) delta = -2.7 per frame, the clearing test's
  // (delta/2) I (0.4 - 0.25) delta = +2.1 against clearing.
  int quiet_frames = 0;
  for (int k = 0; k < 300; ++k) {
    step = evidence.update(source.frame(seq++, {{"a3", 0.4 * 3 * kDeg}}));
    if (step.quiet) ++quiet_frames;
    EXPECT_FALSE(evidence.cleared("a3")) << "frame " << k << ": " << evidence.clearing_summary("a3");
  }
  EXPECT_GE(quiet_frames, 290) << "the stop test alone would have let the diagnosis close";
  EXPECT_LT(evidence.clearing_cusum("a3"), evidence.warning_level());
  EXPECT_EQ(
      evidence.clearing_summary("a3").rfind("evidence a3's fault is gone (clearing test at delta/2): ", 0),
      0u)
      << evidence.clearing_summary("a3");
  // The fault gone: the clearing test gains (delta/2)^2 I / 2 = 3.4 per
  // frame and reaches its level (h = 21.2) within about 6 frames.
  int frames_to_clear = 0;
  while (!evidence.cleared("a3")) {
    ASSERT_LT(frames_to_clear, 20) << evidence.clearing_summary("a3");
    step = evidence.update(source.frame(seq++));
    ++frames_to_clear;
  }
  EXPECT_GE(frames_to_clear, 4);
  EXPECT_DOUBLE_EQ(evidence.clearing_level(), evidence.threshold());
  // A new crossing restarts its clearing test.
  step = evidence.update(source.frame(seq++, {{"a3", 6 * kDeg}}));
  ASSERT_TRUE(step.crossed);
  EXPECT_DOUBLE_EQ(evidence.clearing_cusum("a3"), 0);
  EXPECT_FALSE(evidence.cleared("a3"));
  evidence.reset();
  EXPECT_FALSE(evidence.cleared("a3")) << "a closed diagnosis's tests start afresh, at 0";
}

// ---- Through RiskMonitor: judged in frame order ----

constexpr int64_t kStart = 5'000'000'000;  // monotonic
constexpr int64_t kMs = 1000;

heartbeat_t heartbeat(const std::string& process) {
  heartbeat_t hb{};
  hb.process = process;
  return hb;
}

void feed_all(risk::RiskMonitor* m, int64_t now) {
  m->on_depth(now);
  joint_state_t s{};
  s.num_joints = 1;
  s.name = {"a1"};
  s.position = {0};
  s.velocity = {0.5};
  s.utime = now;  // a new state each time (a repeated one is refused as a duplicate)
  m->on_joint_state(s, now);
  for (const char* p : {"tofguard-camera", "tofguard-renderer", "tofguard-discrepancy"}) {
    m->on_heartbeat(heartbeat(p), now);
  }
}

risk_t judge(risk::RiskMonitor* m, const discrepancy_t& d, int64_t* now) {
  *now += 33 * kMs;
  feed_all(m, *now);
  const std::vector<risk_t> verdicts = m->on_frame(d, *now);
  EXPECT_EQ(verdicts.size(), 1u) << "frame " << d.seq;
  return verdicts.empty() ? risk_t{} : verdicts.front();
}

TEST(RiskMonitorEvidence, AGrossFaultStopsOnItsFirstFrameAndTheSuspectStaysLatched) {
  risk::RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  ScoreSource source(7);
  int64_t now = kStart;
  int64_t seq = 100;
  for (; seq < 110; ++seq) EXPECT_EQ(judge(&m, source.frame(seq), &now).level, risk_t::SAFE);
  // a3 off by 6 degrees (I = 1e4: drift 2 * 27 - 27 / 2 = 41 > h): DANGEROUS on its first frame.
  risk_t r = judge(&m, source.frame(seq++, {{"a3", 6 * kDeg}}), &now);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(r.suspect, "a3");
  const int64_t stop_seq = r.seq;
  // Later a2's evidence grows larger (s^2/I of a2 > a3's): the diagnosis
  // keeps the suspect named at the stop.
  for (int k = 0; k < 20; ++k) {
    r = judge(&m, source.frame(seq++, {{"a3", 6 * kDeg}, {"a2", 5 * kDeg}}), &now);
    EXPECT_EQ(r.level, risk_t::DANGEROUS);
    EXPECT_EQ(r.cause, risk_t::CAUSE_JOINT_ERROR);
    EXPECT_EQ(r.suspect, "a3") << r.detail;
    EXPECT_EQ(r.detail.rfind("diagnosis open since seq " + std::to_string(stop_seq) + ": joint a3", 0), 0u)
        << r.detail;
  }
  EXPECT_NE(r.detail.find("this frame: joint a2"), std::string::npos) << r.detail;
}

// Two cameras' monitors sharing the pooled tests: a fault both see stops
// the arm on the pooled evidence (said in the detail), and neither
// monitor's diagnosis closes while the pooled tests still hold it.
TEST(RiskMonitorEvidence, APooledCrossingStopsAndHoldsTheDiagnosisUntilThePooledTestsClear) {
  const risk::RiskSettings each = risk::several_cameras_evidence_settings(sim_config().risk, 2);
  SequentialEvidence pooled(each, friend_arm(), 2 * kRateHz, /*camera_test=*/false);
  risk::RiskMonitor mast(each, sim_config().channels, friend_arm(), kRateHz, kStart);
  risk::RiskMonitor side(each, sim_config().channels, friend_arm(), kRateHz, kStart);
  mast.set_pooled_evidence(&pooled);
  side.set_pooled_evidence(&pooled);
  ScoreSource mast_scores(21);
  ScoreSource side_scores(22);
  int64_t mast_now = kStart;
  int64_t side_now = kStart;
  int64_t seq = 100;
  risk_t stop;
  const risk::RiskMonitor* stopped = nullptr;  // the monitor whose frame crossed
  for (; seq < 1100 && stopped == nullptr; ++seq) {
    for (risk::RiskMonitor* m : {&mast, &side}) {
      const risk_t r = m == &mast ? judge(m, mast_scores.frame(seq, {{"a5", 3 * kDeg}}), &mast_now)
                                  : judge(m, side_scores.frame(seq, {{"a5", 3 * kDeg}}), &side_now);
      if (r.level == risk_t::DANGEROUS && stopped == nullptr) {
        stop = r;
        stopped = m;
      }
    }
  }
  ASSERT_EQ(stop.level, risk_t::DANGEROUS);
  EXPECT_EQ(stop.cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(stop.suspect, "a5");
  EXPECT_NE(stop.detail.find("pooled over the cameras: joint a5"), std::string::npos) << stop.detail;
  EXPECT_GE(pooled.joint_cusum("a5"), pooled.threshold());
  // The fault gone: the diagnosis of the monitor that stopped stays open
  // until the pooled test of a5 has shown it gone too (its own tests
  // never crossed).
  int clean_frames = 0;
  for (; seq < 3000 && stopped->diagnosis_open(); ++seq) {
    judge(&mast, mast_scores.frame(seq), &mast_now);
    judge(&side, side_scores.frame(seq), &side_now);
    if (!pooled.cleared("a5")) {
      EXPECT_TRUE(stopped->diagnosis_open());
    }
    ++clean_frames;
  }
  EXPECT_FALSE(stopped->diagnosis_open());
  EXPECT_TRUE(pooled.cleared("a5"));
  std::cout << "pooled a5 diagnosis closed after " << clean_frames
            << " frames of each camera without the fault\n";
}

TEST(RiskMonitorEvidence, TheDiagnosisClosesOnlyAfterClearFramesWithoutAnyFinding) {
  const int clear_frames = sim_config().risk.evidence_clear_frames;
  ASSERT_EQ(clear_frames, 10);
  risk::RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  ScoreSource source(9);
  int64_t now = kStart;
  int64_t seq = 1;
  // The camera 2 cm off sideways: a calibration error at once.
  risk_t r = judge(&m, source.frame(seq++, {}, {0.02, 0, 0, 0, 0, 0}), &now);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.cause, risk_t::CAUSE_CALIBRATION_ERROR);
  EXPECT_NE(r.detail.find("fitted correction ("), std::string::npos) << r.detail;
  // The fault persists for 30 frames: never SAFE.
  for (int k = 0; k < 30; ++k) {
    r = judge(&m, source.frame(seq++, {}, {0.02, 0, 0, 0, 0, 0}), &now);
    EXPECT_EQ(r.level, risk_t::DANGEROUS);
    EXPECT_EQ(r.cause, risk_t::CAUSE_CALIBRATION_ERROR);
  }
  // Fixed: the capped camera CUSUM falls below the warning level within a
  // few frames (its weakly seen alternatives drift down slowly), DANGEROUS
  // meanwhile; then clear_frames - 1 clean frames are still DANGEROUS...
  for (int k = 0; r.detail.find("[clean 1/10 frames]") == std::string::npos; ++k) {
    ASSERT_LT(k, 100) << r.detail;
    r = judge(&m, source.frame(seq++), &now);
    EXPECT_EQ(r.level, risk_t::DANGEROUS);
  }
  for (int k = 2; k < clear_frames - 3; ++k) {
    r = judge(&m, source.frame(seq++), &now);
    EXPECT_EQ(r.level, risk_t::DANGEROUS) << k;
    EXPECT_NE(r.detail.find("[clean " + std::to_string(k) + "/10 frames]"), std::string::npos) << r.detail;
  }
  // ... and any finding restarts the count: an unknown object for one frame.
  discrepancy_t object = source.frame(seq++);
  place_unexplained_surface(&object, 0.05, 0.01);
  r = judge(&m, object, &now);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.cause, risk_t::CAUSE_CALIBRATION_ERROR);  // the diagnosis, not the new finding
  EXPECT_NE(r.detail.find("this frame: unknown object"), std::string::npos) << r.detail;
  for (int k = 1; k < clear_frames; ++k) {
    r = judge(&m, source.frame(seq++), &now);
    EXPECT_EQ(r.level, risk_t::DANGEROUS) << k;
    EXPECT_TRUE(m.diagnosis_open());
  }
  r = judge(&m, source.frame(seq++), &now);
  EXPECT_EQ(r.level, risk_t::SAFE) << r.detail;
  EXPECT_FALSE(m.diagnosis_open());
  EXPECT_DOUBLE_EQ(m.evidence().camera_cusum(), 0);
}

// Through the decision rule: a diagnosis stays open while its fault is read
// below delta/2 (every CUSUM below its warning level), and closes once the
// fault is gone.
TEST(RiskMonitorEvidence, ADiagnosisStaysOpenWhileItsFaultIsReadSmallerThanTheTestsDelta) {
  risk::RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  ScoreSource source(23);
  int64_t now = kStart;
  int64_t seq = 1;
  risk_t r = judge(&m, source.frame(seq++, {{"a3", 6 * kDeg}}), &now);
  ASSERT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.suspect, "a3");
  for (int k = 0; k < 300; ++k) {
    r = judge(&m, source.frame(seq++, {{"a3", 0.4 * 3 * kDeg}}), &now);
    EXPECT_EQ(r.level, risk_t::DANGEROUS) << r.detail;
    EXPECT_EQ(r.suspect, "a3");
  }
  EXPECT_TRUE(m.evidence().quiet());
  EXPECT_NE(r.detail.find("[clean 0/10 frames]"), std::string::npos) << r.detail;
  EXPECT_NE(r.detail.find("evidence a3's fault is gone (clearing test at delta/2): "), std::string::npos)
      << r.detail;
  int frames = 0;
  while (r.level != risk_t::SAFE) {
    ASSERT_LT(frames, 40) << r.detail;
    r = judge(&m, source.frame(seq++), &now);
    ++frames;
  }
  // The clearing test's ~6 frames, then clear_frames clean ones.
  EXPECT_GE(frames, sim_config().risk.evidence_clear_frames + 3);
  EXPECT_FALSE(m.diagnosis_open());
}

// A calibration error the naming search named while a joint's test crossed
// (ACameraMoveTheSearchPrefersBy2hIsACalibrationError): the diagnosis closes
// on that joint's clearing test, the evidence that crossed.
TEST(RiskMonitorEvidence, ACameraNamedByTheSearchClosesOnTheCrossedJointsClearingTest) {
  risk::RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  ScoreSource source(29);
  int64_t now = kStart;
  int64_t seq = 1;
  discrepancy_t d = source.frame(seq++, {{"a1", 3 * kDeg}});
  add_search(&d);
  d.joint_search_gain[joint_index("a1")] = 4000;
  d.camera_search_axis = 0;
  d.camera_search_offset = 0.02;
  d.camera_search_gain = 9000;
  risk_t r = judge(&m, d, &now);
  ASSERT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.cause, risk_t::CAUSE_CALIBRATION_ERROR) << r.detail;
  r = judge(&m, source.frame(seq++), &now);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_NE(r.detail.find("evidence a1's fault is gone (clearing test at delta/2): "), std::string::npos)
      << r.detail;
}

// A sensor fault's diagnosis stays open too.
TEST(RiskMonitorEvidence, ASensorFaultsDiagnosisStaysOpen) {
  risk::RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  ScoreSource source(11);
  int64_t now = kStart;
  discrepancy_t unusable = source.frame(1);
  unusable.usable = false;
  unusable.evidence_available = false;
  unusable.unusable_kind = discrepancy_t::UNUSABLE_RENDERER;
  unusable.unusable_reason = "renderer: joint a3 missing";
  EXPECT_EQ(judge(&m, unusable, &now).level, risk_t::WARNING);
  unusable.seq = 2;
  EXPECT_EQ(judge(&m, unusable, &now).level, risk_t::DANGEROUS);
  for (int64_t seq = 3; seq < 3 + 9; ++seq) {
    const risk_t r = judge(&m, source.frame(seq), &now);
    EXPECT_EQ(r.level, risk_t::DANGEROUS);
    EXPECT_EQ(r.cause, risk_t::CAUSE_SENSOR_FAULT);
    EXPECT_EQ(r.suspect, sim_config().channels.labels);
  }
  EXPECT_EQ(judge(&m, source.frame(12), &now).level, risk_t::SAFE);
}

// With an estimate wait, frames queue behind a waiting one and the tests
// still see them in frame order: the verdicts come in order, the stop at
// the first faulty frame.
TEST(RiskMonitorEvidence, FramesQueuedBehindAnEstimateWaitAreJudgedInOrder) {
  deployment::Config config = sim_config();
  config.risk.estimate_wait_us = 60 * kMs;
  risk::RiskMonitor m(config.risk, config.channels, friend_arm(), kRateHz, kStart);
  ScoreSource source(13);
  int64_t now = kStart;
  feed_all(&m, now);
  discrepancy_t object = source.frame(1);
  place_unexplained_surface(&object, 0.05, 0.01);  // an unknown object: a model mismatch that waits
  EXPECT_TRUE(m.on_frame(object, now).empty());
  now += 20 * kMs;
  feed_all(&m, now);
  EXPECT_TRUE(m.on_frame(source.frame(2, {{"a2", 3 * kDeg}}), now).empty());
  now += 20 * kMs;
  feed_all(&m, now);
  EXPECT_TRUE(m.on_frame(source.frame(3, {{"a2", 3 * kDeg}}), now).empty());
  now += 30 * kMs;
  feed_all(&m, now);
  const std::vector<risk_t> verdicts = m.release_due(now);
  ASSERT_EQ(verdicts.size(), 3u);
  EXPECT_EQ(verdicts[0].seq, 1);
  EXPECT_EQ(verdicts[0].level, risk_t::WARNING);
  EXPECT_EQ(verdicts[0].cause, risk_t::CAUSE_UNKNOWN_OBJECT);
  EXPECT_EQ(verdicts[1].seq, 2);
  EXPECT_EQ(verdicts[1].level, risk_t::DANGEROUS);
  EXPECT_EQ(verdicts[1].suspect, "a2");
  EXPECT_EQ(verdicts[2].seq, 3);
  EXPECT_EQ(verdicts[2].suspect, "a2");
}

}  // namespace
}  // namespace tofguard::test
