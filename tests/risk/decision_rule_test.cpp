// The decision rule on its own: findings debounced into WARNING/DANGEROUS
// in frame order, clean frames SAFE, expired deadlines DANGEROUS at once.
#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "tofguard/risk/decision_rule.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::test {
namespace {

using risk::DecisionRule;
using risk::FrameFinding;

risk::RiskSettings debounce(int model_mismatch_frames, int fault_frames) {
  risk::RiskSettings r;
  r.debounce_frames = model_mismatch_frames;
  r.sensor_debounce_frames = fault_frames;
  return r;
}

discrepancy_t frame(int64_t seq) {
  discrepancy_t d{};
  d.utime = 1'700'000'000'000'000 + seq * 33'333;
  d.seq = seq;
  d.num_compared = 1000;
  d.num_match = 990;
  d.mismatch_fraction = 0.01f;
  return d;
}

FrameFinding joint_error() {
  return FrameFinding{risk_t::CAUSE_JOINT_ERROR, "a4", 0.4, 0.1, "joint a4 reads other than seen"};
}

FrameFinding sensor_fault() {
  return FrameFinding{risk_t::CAUSE_SENSOR_FAULT, "TOF_DEPTH", 0.7, 0.5, "invalid pixels"};
}

TEST(DecisionRule, AFindingIsWarningUntilItHeldForTheDebounceCountAndOneCleanFrameResetsIt) {
  DecisionRule rule(debounce(3, 2));
  const std::vector<std::pair<int8_t, std::string>> expected = {
      {risk_t::WARNING, " [1/3 frames]"},
      {risk_t::WARNING, " [2/3 frames]"},
      {risk_t::DANGEROUS, " [3/3 frames]"},
  };
  for (size_t i = 0; i < expected.size(); ++i) {
    const risk_t r = rule.decide(frame(100 + i), joint_error(), std::nullopt);
    EXPECT_EQ(r.level, expected[i].first) << i;
    EXPECT_EQ(r.detail, "joint a4 reads other than seen" + expected[i].second);
    EXPECT_EQ(r.seq, static_cast<int64_t>(100 + i));
    EXPECT_EQ(r.utime, frame(100 + i).utime);
    EXPECT_EQ(r.cause, risk_t::CAUSE_JOINT_ERROR);
    EXPECT_EQ(r.suspect, "a4");
    EXPECT_DOUBLE_EQ(r.score, 0.4);
    EXPECT_DOUBLE_EQ(r.threshold, 0.1);
  }
  // The stop opened a diagnosis: the next frame is DANGEROUS with the stop's
  // finding, whatever it shows.
  EXPECT_TRUE(rule.diagnosis_open());
  const risk_t open = rule.decide(frame(103), joint_error(), std::nullopt);
  EXPECT_EQ(open.level, risk_t::DANGEROUS);
  EXPECT_EQ(
      open.detail,
      "diagnosis open since seq 102: joint a4 reads other than seen [3/3 frames]; this frame: joint a4 reads "
      "other than seen [clean 0/1 frames]");
  EXPECT_EQ(rule.consecutive_findings(), 4);

  // risk.evidence.clear_frames = 1 here: one clean frame closes it.

  const risk_t clean = rule.decide(frame(104), FrameFinding{}, std::nullopt);
  EXPECT_EQ(clean.level, risk_t::SAFE);
  EXPECT_EQ(clean.cause, risk_t::CAUSE_NONE);
  EXPECT_FLOAT_EQ(static_cast<float>(clean.score), 0.01f);  // the mismatch fraction
  EXPECT_EQ(clean.detail, "model and camera agree (mismatch fraction): 10 of 1000 compared pixels differ");
  EXPECT_EQ(rule.consecutive_findings(), 0);

  EXPECT_EQ(rule.decide(frame(105), joint_error(), std::nullopt).level, risk_t::WARNING);
}

TEST(DecisionRule, FaultsUseTheSensorDebounceAndTheCountRunsAcrossCauses) {
  DecisionRule rule(debounce(3, 2));
  risk_t r = rule.decide(frame(1), sensor_fault(), std::nullopt);
  EXPECT_EQ(r.level, risk_t::WARNING);
  EXPECT_EQ(r.detail, "invalid pixels [1/2 frames]");
  r = rule.decide(frame(2), sensor_fault(), std::nullopt);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.detail, "invalid pixels [2/2 frames]");
  // Consecutive frames with any finding count: the third is DANGEROUS as a
  // model mismatch as well.
  // The sensor fault's diagnosis stays open with its cause and suspect.
  r = rule.decide(frame(3), joint_error(), std::nullopt);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(r.suspect, "TOF_DEPTH");
  EXPECT_EQ(
      r.detail,
      "diagnosis open since seq 2: invalid pixels [2/2 frames]; this frame: joint a4 reads other than seen "
      "[clean 0/1 frames]");
  EXPECT_EQ(rule.consecutive_findings(), 3);
}

// A crossed sequential test is DANGEROUS at once, growing evidence only
// WARNING; a diagnosis closes after clear_frames frames without any finding
// and with the evidence quiet, and any finding restarts the count.
TEST(DecisionRule, SequentialFindingsAndTheDiagnosisThatStaysOpen) {
  risk::RiskSettings settings = debounce(3, 2);
  settings.evidence_clear_frames = 3;
  DecisionRule rule(settings);
  FrameFinding growing = joint_error();
  growing.warning_only = true;
  for (int i = 0; i < 5; ++i) {
    const risk_t r = rule.decide(frame(10 + i), growing, std::nullopt);
    EXPECT_EQ(r.level, risk_t::WARNING);
    EXPECT_EQ(r.detail, "joint a4 reads other than seen");
  }
  EXPECT_EQ(rule.decide(frame(15), FrameFinding{}, std::nullopt).level, risk_t::SAFE);
  FrameFinding crossed = joint_error();
  crossed.at_once = true;
  risk_t r = rule.decide(frame(16), crossed, std::nullopt);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.detail, "joint a4 reads other than seen");
  FrameFinding other{risk_t::CAUSE_JOINT_ERROR, "a5", 30, 20, "joint a5 reads other than seen"};
  other.at_once = true;
  r = rule.decide(frame(17), other, std::nullopt);
  EXPECT_EQ(r.suspect, "a4");
  // Clean frames, but the evidence not yet quiet: not counted.
  r = rule.decide(frame(18), FrameFinding{}, std::nullopt, /*evidence_quiet=*/false, "evidence: a4 12.0");
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.detail,
            "diagnosis open since seq 16: joint a4 reads other than seen; this frame: no finding; evidence: "
            "a4 12.0 "
            "[clean 0/3 frames]");
  EXPECT_EQ(rule.decide(frame(19), FrameFinding{}, std::nullopt).level, risk_t::DANGEROUS);
  EXPECT_EQ(rule.clean_frames(), 1);
  EXPECT_EQ(rule.decide(frame(20), FrameFinding{}, std::nullopt).level, risk_t::DANGEROUS);
  EXPECT_EQ(rule.clean_frames(), 2);
  // A finding (even a mere warning) restarts the count.
  EXPECT_EQ(rule.decide(frame(21), growing, std::nullopt).level, risk_t::DANGEROUS);
  EXPECT_EQ(rule.clean_frames(), 0);
  // So does an expired deadline.
  const FrameFinding stale{risk_t::CAUSE_SENSOR_FAULT, "JOINT_STATE", 101, 100, "JOINT_STATE stale"};
  EXPECT_EQ(rule.decide(frame(22), FrameFinding{}, std::nullopt).level, risk_t::DANGEROUS);
  EXPECT_EQ(rule.decide(frame(23), FrameFinding{}, stale).detail, "timeout: JOINT_STATE stale");
  EXPECT_EQ(rule.clean_frames(), 0);
  for (int i = 0; i < 2; ++i)
    EXPECT_EQ(rule.decide(frame(24 + i), FrameFinding{}, std::nullopt).level, risk_t::DANGEROUS);
  EXPECT_TRUE(rule.diagnosis_open());
  EXPECT_EQ(rule.decide(frame(26), FrameFinding{}, std::nullopt).level, risk_t::SAFE);
  EXPECT_FALSE(rule.diagnosis_open());
}

TEST(DecisionRule, AnExpiredDeadlineIsDangerousAtOnceAndTheFrameStillCounts) {
  DecisionRule rule(debounce(3, 2));
  const FrameFinding stale{risk_t::CAUSE_SENSOR_FAULT, "JOINT_STATE", 101, 100,
                           "JOINT_STATE stale (age ms): nothing for 101 ms, deadline 100 ms"};
  // Even a clean frame.
  risk_t r = rule.decide(frame(7), FrameFinding{}, stale);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.seq, 7);
  EXPECT_EQ(r.cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(r.suspect, "JOINT_STATE");
  EXPECT_DOUBLE_EQ(r.score, 101);
  EXPECT_DOUBLE_EQ(r.threshold, 100);
  EXPECT_EQ(r.detail, "timeout: JOINT_STATE stale (age ms): nothing for 101 ms, deadline 100 ms");

  r = rule.decide(frame(8), joint_error(), stale);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.suspect, "JOINT_STATE");
  // The frame judged under the timeout counted: this one is the second.
  r = rule.decide(frame(9), joint_error(), std::nullopt);
  EXPECT_EQ(r.level, risk_t::WARNING);
  EXPECT_EQ(r.detail, "joint a4 reads other than seen [2/3 frames]");
}

TEST(DecisionRule, TheTimeoutVerdictHasNoFrameAndTheLastFramesUtime) {
  const FrameFinding stale{risk_t::CAUSE_COMPONENT_FAULT, "tofguard-renderer", 300, 250,
                           "tofguard-renderer heartbeat"};
  const risk_t r = risk::timeout_verdict(1'700'000'000'123'456, stale);
  EXPECT_EQ(r.seq, -1);
  EXPECT_EQ(r.utime, 1'700'000'000'123'456);
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.cause, risk_t::CAUSE_COMPONENT_FAULT);
  EXPECT_EQ(r.detail, "timeout: tofguard-renderer heartbeat");
}

}  // namespace
}  // namespace tofguard::test
