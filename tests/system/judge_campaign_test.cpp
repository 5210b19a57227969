// The judgement (renderer -> discrepancy -> risk, in-process with the real
// EGL renderer, the simulated ToF camera's error model and the config's
// settings) on the default arm, the iiwa14 and the Kinova Gen3 (../shared,
// skipped when absent): issue 14's targets on a short campaign (every joint
// 5 degrees off, the camera moved 2 cm along its optical axis and sideways
// and turned 1 degree), and issue 15's objects (a cube inside the protective
// field, a person and a cart beyond the warning field).
// tofguard-judge-campaign runs the long ones (docs/safety-chain.md,
// "Measured"; docs/detection.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

#include "judge_campaign.hpp"
#include "test_support.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::test {
namespace {

int sim_config_debounce_frames() { return default_campaign_arm().config.risk.debounce_frames; }

std::vector<CampaignRun> short_runs(const CampaignArm& arm) {
  std::vector<CampaignRun> runs;
  for (CampaignRun& run : standard_fault_runs(arm, {5})) {
    const std::string& label = run.fault.label;
    // The joints, and three of the camera cases.
    if (run.fault.kind == CampaignFault::Kind::kCameraPose && label != "camera 2 cm along z (optical axis)" &&
        label != "camera 2 cm along y" && label != "camera turned 1 deg about y") {
      continue;
    }
    run.frames_after_onset = 15;
    runs.push_back(run);
  }
  return runs;
}

// Issue 15's objects: a 10 cm cube 10 and 40 cm from the arm (inside the
// protective field: stopped within the debounce), a person and a cart
// walking past beyond the warning field (never a stop).
void expect_object_targets(const CampaignArm& arm) {
  std::vector<CampaignRun> runs;
  for (CampaignRun run : object_runs(arm, {0.10, 0.40}, 0.10)) {
    if (run.fault.label.rfind("hand", 0) == 0) continue;
    run.frames_after_onset = 20;  // the stop comes on the 3rd; 2/3 s of walking past
    runs.push_back(run);
  }
  const std::vector<CampaignResult> results = run_campaign(arm, runs);
  std::cout << object_report(arm.name, results, arm.config);
  int objects = 0;
  int passers = 0;
  for (const CampaignResult& r : results) {
    SCOPED_TRACE(arm.name + ", " + r.label);
    EXPECT_FALSE(r.false_stop) << r.false_stop_detail;
    if (r.label.rfind("object", 0) == 0) {
      ++objects;
      EXPECT_GE(r.object_pixels, 100);
      EXPECT_TRUE(r.stopped);
      // (An object right beside a link may be named a joint error; the arm
      // stops either way. docs/detection.md counts the causes.)
      EXPECT_LE(r.stop_frames, sim_config_debounce_frames()) << r.detail;
    } else {
      ++passers;
      EXPECT_GT(r.object_distance_at_onset_m, 1.0);
      EXPECT_FALSE(r.stopped) << r.detail;
    }
  }
  EXPECT_EQ(objects, 4);
  EXPECT_EQ(passers, 4);
}

void expect_targets(const CampaignArm& arm) {
  expect_object_targets(arm);
  const std::vector<CampaignResult> results = run_campaign(arm, short_runs(arm));
  std::cout << campaign_report(arm.name, results, 1.0 / arm.config.camera.rate_hz);
  int observable_joint_faults = 0;
  int right_suspects = 0;
  std::vector<int> stop_frames;
  for (const CampaignResult& r : results) {
    SCOPED_TRACE(arm.name + ", " + r.label);
    EXPECT_FALSE(r.false_stop) << r.false_stop_detail;
    if (r.label.rfind("camera", 0) == 0) {
      EXPECT_TRUE(r.stopped);
      EXPECT_EQ(r.cause, risk_t::CAUSE_CALIBRATION_ERROR) << r.detail;
      EXPECT_LE(r.stop_frames, 2) << r.detail;
    } else {
      // An offset that changes (almost) no pixel by 3 sigma (a symmetric
      // last link turning about its own axis: 0 or 1 pixels) is invisible
      // to any camera; a wrist's 5 degrees change 15-25 pixels by that much
      // and are found from the evidence of hundreds of pixels together.
      if (r.changed_pixels < 5) continue;
      ++observable_joint_faults;
      EXPECT_TRUE(r.stopped) << r.changed_pixels << " pixels changed";
      EXPECT_EQ(r.cause, risk_t::CAUSE_JOINT_ERROR) << r.detail;
      right_suspects += r.right_suspect ? 1 : 0;
    }
    if (r.stopped) stop_frames.push_back(r.stop_frames);
    // The diagnosis persists: no SAFE verdict, no other suspect while the
    // fault does.
    EXPECT_EQ(r.safe_after_stop, 0);
    EXPECT_EQ(r.suspect_changes, 0);
  }
  EXPECT_GE(observable_joint_faults, 6);
  // The suspect at the stop: every one right (the naming search; with the
  // linear naming fit alone the iiwa14 had 4 of 6, its shoulder joints 1
  // and 3, 2 and 4 turning about nearly parallel axes in this pose).
  EXPECT_EQ(right_suspects, observable_joint_faults);
  ASSERT_FALSE(stop_frames.empty());
  std::sort(stop_frames.begin(), stop_frames.end());
  EXPECT_LE(stop_frames[stop_frames.size() / 2], 2) << "median frames from onset to stop";
}

TEST(JudgeCampaign, DefaultArm) { expect_targets(default_campaign_arm()); }

TEST(JudgeCampaign, Iiwa14) {
  const std::optional<CampaignArm> arm = iiwa14_campaign_arm(shared_dir(), output_dir() + "/judge_campaign");
  if (!arm)
    GTEST_SKIP() << "the iiwa14 is not under ../shared/robots (shared_dir() '" << shared_dir() << "')";
  expect_targets(*arm);
}

TEST(JudgeCampaign, KinovaGen3) {
  const std::optional<CampaignArm> arm =
      kinova_gen3_campaign_arm(shared_dir(), output_dir() + "/judge_campaign");
  if (!arm)
    GTEST_SKIP() << "the Kinova Gen3 is not under ../shared/robots (shared_dir() '" << shared_dir() << "')";
  expect_targets(*arm);
}

}  // namespace
}  // namespace tofguard::test
