// The one verdict stream of several cameras (verdict_fusion.hpp): every
// published verdict is the worst of every camera's latest, so no camera's
// stop, open diagnosis or silence is hidden by another camera's view; and
// the links no camera sees (arm_coverage.hpp).
#include "tofguard/risk/verdict_fusion.hpp"

#include <gtest/gtest.h>

#include "tofguard/risk/arm_coverage.hpp"

namespace tofguard::risk {
namespace {

risk_t verdict(int64_t seq, int8_t level, int8_t cause = risk_t::CAUSE_NONE,
               const std::string& detail = "ok") {
  risk_t r;
  r.utime = 1000 + seq;
  r.seq = seq;
  r.level = level;
  r.cause = cause;
  r.suspect = "";
  r.detail = detail;
  return r;
}

VerdictFusion two_cameras() {
  return VerdictFusion({"tof-mast", "tof-side"}, {"TOF_DEPTH", "TOF_DEPTH/tof-side"});
}

TEST(VerdictFusion, OneCameraPassesEveryVerdictAsItIs) {
  VerdictFusion fusion({"tof-mast"}, {"TOF_DEPTH"});
  const risk_t out = *fusion.fuse(0, verdict(7, risk_t::SAFE));
  EXPECT_EQ(out.seq, 7);
  EXPECT_EQ(out.level, risk_t::SAFE);
  EXPECT_EQ(out.detail, "ok");
}

TEST(VerdictFusion, ACameraWithoutAVerdictKeepsTheArmStoppedAndIsNamed) {
  VerdictFusion fusion = two_cameras();
  const risk_t out = *fusion.fuse(0, verdict(1, risk_t::SAFE));
  EXPECT_EQ(out.level, risk_t::DANGEROUS);
  EXPECT_EQ(out.cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(out.suspect, "TOF_DEPTH/tof-side");
  EXPECT_EQ(out.detail, "tof-side: no frame of this camera judged yet");
  // Once both have judged a frame, the safe verdicts pass, named.
  fusion.fuse(1, verdict(1, risk_t::SAFE));
  const risk_t both = *fusion.fuse(0, verdict(2, risk_t::SAFE));
  EXPECT_EQ(both.level, risk_t::SAFE);
  EXPECT_EQ(both.seq, 2);
  EXPECT_EQ(both.detail, "tof-mast: ok");
}

TEST(VerdictFusion, OneCamerasStopHoldsWhateverTheOtherSees) {
  VerdictFusion fusion = two_cameras();
  fusion.fuse(0, verdict(1, risk_t::SAFE));
  fusion.fuse(1, verdict(1, risk_t::SAFE));
  const risk_t side_stop =
      *fusion.fuse(1, verdict(2, risk_t::DANGEROUS, risk_t::CAUSE_CALIBRATION_ERROR, "camera moved"));
  EXPECT_EQ(side_stop.level, risk_t::DANGEROUS);
  EXPECT_EQ(side_stop.detail, "tof-side: camera moved");
  // The mast camera's safe frames do not clear it: the side camera's
  // diagnosis is published with each of them.
  for (int64_t seq = 2; seq < 5; ++seq) {
    const risk_t out = *fusion.fuse(0, verdict(seq, risk_t::SAFE));
    EXPECT_EQ(out.level, risk_t::DANGEROUS);
    EXPECT_EQ(out.cause, risk_t::CAUSE_CALIBRATION_ERROR);
    EXPECT_EQ(out.detail, "tof-side: camera moved");
  }
  // A warning of the mast camera is less than the side camera's stop.
  EXPECT_EQ(fusion.fuse(0, verdict(5, risk_t::WARNING))->detail, "tof-side: camera moved");
  // The side camera's diagnosis closes: the mast camera's warning is the worst.
  const risk_t cleared = *fusion.fuse(1, verdict(3, risk_t::SAFE));
  EXPECT_EQ(cleared.level, risk_t::WARNING);
  EXPECT_EQ(cleared.detail, "tof-mast: ok");
}

// Both cameras DANGEROUS: the first finding is published while it holds
// (a knocked camera, then a joint test the other camera's frames push
// over, is published as the knock), whichever camera's frame comes; once
// it clears, the other's.
TEST(VerdictFusion, AmongStoppedCamerasTheFirstFindingIsPublished) {
  VerdictFusion fusion = two_cameras();
  fusion.fuse(0, verdict(1, risk_t::SAFE));
  fusion.fuse(1, verdict(1, risk_t::SAFE));
  fusion.fuse(1, verdict(2, risk_t::DANGEROUS, risk_t::CAUSE_CALIBRATION_ERROR, "camera moved"));
  const risk_t later = *fusion.fuse(0, verdict(2, risk_t::DANGEROUS, risk_t::CAUSE_JOINT_ERROR, "joint a5"));
  EXPECT_EQ(later.cause, risk_t::CAUSE_CALIBRATION_ERROR);
  EXPECT_EQ(later.detail, "tof-side: camera moved");
  for (int64_t seq = 3; seq < 6; ++seq) {
    EXPECT_EQ(fusion.fuse(0, verdict(seq, risk_t::DANGEROUS, risk_t::CAUSE_JOINT_ERROR, "joint a5"))->detail,
              "tof-side: camera moved");
    EXPECT_EQ(
        fusion.fuse(1, verdict(seq, risk_t::DANGEROUS, risk_t::CAUSE_CALIBRATION_ERROR, "camera moved"))
            ->detail,
        "tof-side: camera moved");
  }
  // The side camera's finding clears: the mast camera's is the worst.
  const risk_t cleared = *fusion.fuse(1, verdict(6, risk_t::SAFE));
  EXPECT_EQ(cleared.cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(cleared.detail, "tof-mast: joint a5");
  // Equal warnings: the newest.
  VerdictFusion warnings = two_cameras();
  warnings.fuse(0, verdict(1, risk_t::WARNING, risk_t::CAUSE_NONE, "near"));
  EXPECT_EQ(warnings.fuse(1, verdict(1, risk_t::WARNING, risk_t::CAUSE_NONE, "nearer"))->detail,
            "tof-side: nearer");
}

TEST(VerdictFusion, AStalledCamerasTimeoutHoldsUntilItsNextVerdict) {
  VerdictFusion fusion = two_cameras();
  fusion.fuse(0, verdict(1, risk_t::SAFE));
  fusion.fuse(1, verdict(1, risk_t::SAFE));
  risk_t timeout = verdict(-1, risk_t::DANGEROUS, risk_t::CAUSE_SENSOR_FAULT, "TOF_DEPTH/tof-side stale");
  timeout.suspect = "TOF_DEPTH/tof-side";
  fusion.fuse(1, timeout);
  const risk_t out = *fusion.fuse(0, verdict(2, risk_t::SAFE));
  EXPECT_EQ(out.level, risk_t::DANGEROUS);
  EXPECT_EQ(out.seq, -1);
  EXPECT_EQ(out.suspect, "TOF_DEPTH/tof-side");
  EXPECT_EQ(out.detail, "tof-side: TOF_DEPTH/tof-side stale");
}

// A verdict about no frame (seq -1) while another camera's latest frame
// verdict is worse publishes that verdict, but as about no frame: its
// frame's verdict went out once already, and a second with its seq would
// count as another frame judged (a replay's frames and verdicts).
TEST(VerdictFusion, AVerdictAboutNoFramePublishesNoFramesVerdictAgain) {
  VerdictFusion fusion = two_cameras();
  const risk_t unusable =
      *fusion.fuse(0, verdict(6, risk_t::WARNING, risk_t::CAUSE_SENSOR_FAULT, "unusable"));
  EXPECT_EQ(unusable.seq, 6);
  EXPECT_EQ(fusion.fuse(1, verdict(6, risk_t::SAFE))->seq, 6);  // the mast camera's WARNING, as it was
  const risk_t out = *fusion.fuse(1, verdict(-1, risk_t::SAFE, risk_t::CAUSE_NONE, "inputs fresh"));
  EXPECT_EQ(out.level, risk_t::WARNING);
  EXPECT_EQ(out.detail, "tof-mast: unusable");
  EXPECT_EQ(out.seq, -1);
  // A frame verdict still publishes the winner's seq.
  EXPECT_EQ(fusion.fuse(1, verdict(7, risk_t::SAFE))->seq, 6);
}

// risk.camera_loss continue_after_named_reset: a lost camera released by
// name is left out, said in every verdict, until it judges SAFE again.
TEST(VerdictFusion, AReleasedLostCameraIsLeftOutAndSaidUntilItIsBack) {
  VerdictFusion fusion({"tof-mast", "tof-side"}, {"TOF_DEPTH", "TOF_DEPTH/tof-side"},
                       /*releases_allowed=*/true);
  fusion.fuse(0, verdict(1, risk_t::SAFE));
  // Not lost: nothing to release.
  fusion.fuse(1, verdict(1, risk_t::SAFE));
  EXPECT_EQ(fusion.release(1, "nurse", "camera knocked"),
            "refused: tof-side is not lost: its latest verdict is SAFE");
  risk_t timeout = verdict(-1, risk_t::DANGEROUS, risk_t::CAUSE_SENSOR_FAULT, "TOF_DEPTH/tof-side stale");
  fusion.fuse(1, timeout);
  EXPECT_EQ(fusion.fuse(0, verdict(2, risk_t::SAFE))->level, risk_t::DANGEROUS);
  // The last camera judging cannot be released; the lost one can.
  EXPECT_EQ(fusion.release(0, "nurse", "x"), "refused: tof-mast is not lost: its latest verdict is SAFE");
  EXPECT_EQ(fusion.release(1, "nurse", "side camera unplugged"), "");
  EXPECT_TRUE(fusion.released(1));
  const risk_t without = *fusion.fuse(0, verdict(3, risk_t::SAFE));
  EXPECT_EQ(without.level, risk_t::SAFE);
  EXPECT_EQ(without.detail, "tof-mast: ok [tof-side left out: released by nurse: side camera unplugged]");
  // Its timeouts go on and publish nothing; the mast camera still stops the arm.
  EXPECT_FALSE(fusion.fuse(1, timeout).has_value());
  EXPECT_EQ(fusion.release(0, "nurse", "x"), "refused: tof-mast is not lost: its latest verdict is SAFE");
  EXPECT_EQ(fusion.fuse(0, verdict(4, risk_t::DANGEROUS, risk_t::CAUSE_JOINT_ERROR, "a3"))->level,
            risk_t::DANGEROUS);
  EXPECT_EQ(fusion.release(0, "nurse", "x"),
            "refused: tof-mast's finding is a joint error, not a fault of the "
            "camera: it holds (tof-mast: a3)");
  fusion.fuse(0, verdict(5, risk_t::SAFE));
  // Back: its first SAFE frame verdict counts it again.
  const risk_t back = *fusion.fuse(1, verdict(9, risk_t::SAFE));
  EXPECT_FALSE(fusion.released(1));
  EXPECT_EQ(back.detail, "tof-side: ok");
  EXPECT_EQ(fusion.fuse(1, timeout)->level, risk_t::DANGEROUS);
}

TEST(VerdictFusion, WithCameraLossStopNoCameraIsReleased) {
  VerdictFusion fusion = two_cameras();
  fusion.fuse(0, verdict(1, risk_t::SAFE));
  fusion.fuse(1, verdict(-1, risk_t::DANGEROUS, risk_t::CAUSE_SENSOR_FAULT, "stale"));
  EXPECT_EQ(fusion.release(1, "nurse", "x"),
            "refused: risk.camera_loss is stop: a lost camera stops the arm until it is back");
  EXPECT_EQ(fusion.fuse(0, verdict(2, risk_t::SAFE))->level, risk_t::DANGEROUS);
}

// A frame of an arm with a root frame (no geometry, never rendered), two
// links and a gripper, and a table.
discrepancy_t frame_seeing(const std::vector<int>& compared, const std::vector<int>& nearer) {
  discrepancy_t f{};
  f.usable = true;
  f.num_robot_links = 4;
  f.num_links = 5;
  f.link_name = {"world", "link1", "link2", "gripper", "table"};
  f.link_compared = {0, compared[0], compared[1], compared[2], 500};
  f.link_nearer = {0, nearer[0], nearer[1], nearer[2], 0};
  f.link_invalid = {0, 0, 0, 1, 0};
  return f;
}

// The arm's links and their surface areas (m^2): link1 half the arm,
// link2 a quarter, the gripper and link3 an eighth each; the root frame
// has no surface.
const std::vector<LinkArea> kLinkAreas = {
    {"world", 0.0}, {"link1", 0.2}, {"link2", 0.1}, {"gripper", 0.05}, {"link3", 0.05}};

// The links no camera sees: a link is seen by a camera whose latest frame
// compares at least min_link_pixels of it (pixels hidden by the user or a
// far object are not compared: the discrepancy takes them as without a
// return). A link in no camera's view (link3, not in the frames) is unseen.
TEST(ArmCoverage, ALinkIsUnseenOnlyWhenNoCountedCameraSeesIt) {
  ArmCoverage coverage(2, /*min_link_pixels=*/30, kLinkAreas);
  EXPECT_DOUBLE_EQ(coverage.total_area_m2(), 0.4);
  EXPECT_TRUE(coverage.unseen_links({true, true}).empty()) << "no frame yet: nothing to say";
  // The mast camera sees link1 only: the user's arm hides most of link2
  // (20 compared) and the gripper is out of its view.
  coverage.on_frame(0, frame_seeing({100, 20, 0}, {0, 0, 0}));
  EXPECT_TRUE(coverage.unseen_links({true, true}).empty()) << "the side camera has had no frame";
  EXPECT_EQ(coverage.unseen_links({true, false}), (std::vector<std::string>{"link2", "gripper", "link3"}));
  EXPECT_DOUBLE_EQ(coverage.area_fraction(coverage.unseen_links({true, false})), 0.5);
  // The side camera sees link2 and the gripper (5 of its pixels nearer: a
  // moved link or something against it, judged by that camera).
  coverage.on_frame(1, frame_seeing({0, 60, 35}, {0, 0, 5}));
  EXPECT_EQ(coverage.unseen_links({true, true}), (std::vector<std::string>{"link3"}));
  // Its next frame sees the gripper with only 29 px: unseen by both.
  coverage.on_frame(1, frame_seeing({0, 60, 29}, {0, 0, 5}));
  const std::vector<std::string> unseen = coverage.unseen_links({true, true});
  EXPECT_EQ(unseen, (std::vector<std::string>{"gripper", "link3"}));
  EXPECT_DOUBLE_EQ(coverage.area_fraction(unseen), 0.25);
  EXPECT_EQ(unseen_links_text(unseen, coverage.area_fraction(unseen)),
            " [seen by no camera: gripper, link3 (25 % of the arm's surface)]");
  // An unusable frame says nothing about the links.
  discrepancy_t unusable = frame_seeing({0, 0, 0}, {0, 0, 0});
  unusable.usable = false;
  coverage.on_frame(1, unusable);
  EXPECT_EQ(coverage.unseen_links({true, true}), (std::vector<std::string>{"gripper", "link3"}));
  EXPECT_EQ(unseen_links_text({}, 0), "");
}

// An area that is not a surface is a fault in the model, not a link to
// leave out.
TEST(ArmCoverage, ANegativeOrUndefinedAreaIsRefused) {
  EXPECT_THROW(ArmCoverage(2, 30, {{"link1", -0.1}}), std::invalid_argument);
  EXPECT_THROW(ArmCoverage(2, 30, {{"link1", std::nan("")}}), std::invalid_argument);
}

// More than risk.unseen_arm_max_fraction of the arm's surface seen by no
// camera: the verdict is DANGEROUS and says which links and what share;
// at the limit, or a verdict DANGEROUS already, unchanged. The share is
// of area, not of links: link1 alone (half the arm) is at the limit, link1
// with the gripper beyond it, three small links far below it.
TEST(ArmCoverage, MoreOfTheArmUnseenThanTheLimitStopsIt) {
  const ArmCoverage coverage(2, 30, kLinkAreas);
  risk_t safe{};
  safe.level = risk_t::SAFE;
  safe.detail = "tof-side: frame matches";
  risk_t r = safe;
  const std::vector<std::string> small = {"link2", "gripper", "link3"};
  EXPECT_FALSE(limit_unseen_arm(small, coverage.area_fraction(small), 0.5, &r));
  EXPECT_FALSE(limit_unseen_arm({"link1"}, coverage.area_fraction({"link1"}), 0.5, &r));
  EXPECT_EQ(r.level, risk_t::SAFE);
  const std::vector<std::string> large = {"link1", "gripper"};
  EXPECT_TRUE(limit_unseen_arm(large, coverage.area_fraction(large), 0.5, &r));
  EXPECT_EQ(r.level, risk_t::DANGEROUS);
  EXPECT_EQ(r.cause, risk_t::CAUSE_UNCLASSIFIED);
  EXPECT_EQ(r.suspect, "risk.unseen_arm_max_fraction");
  EXPECT_DOUBLE_EQ(r.score, 0.625);
  EXPECT_DOUBLE_EQ(r.threshold, 0.5);
  EXPECT_EQ(
      r.detail,
      "arm not seen (fraction of the arm's surface): link1, gripper, 63 % of the arm's surface seen by no "
      "camera, limit 50 %; tof-side: frame matches");
  risk_t dangerous = safe;
  dangerous.level = risk_t::DANGEROUS;
  dangerous.cause = risk_t::CAUSE_JOINT_ERROR;
  EXPECT_FALSE(limit_unseen_arm(large, coverage.area_fraction(large), 0.5, &dangerous));
  EXPECT_EQ(dangerous.cause, risk_t::CAUSE_JOINT_ERROR);
  r = safe;
  EXPECT_FALSE(limit_unseen_arm({}, 0, 0.5, &r)) << "nothing unseen";
}

}  // namespace
}  // namespace tofguard::risk
