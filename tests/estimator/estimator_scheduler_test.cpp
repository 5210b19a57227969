// tofguard-estimator's scheduler without LCM or rendering: which frames an
// estimate is made of (estimator.frames_per_estimate, docs/estimator.md).
#include <gtest/gtest.h>

#include <memory>

#include "estimator_test_support.hpp"
#include "tofguard/common/camera_profile.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/estimator/estimator_process.hpp"
#include "tofguard/estimator/estimator_scheduler.hpp"

namespace tofguard::estimator {
namespace {

constexpr int64_t kStartUtime = 1'000'000'000;
constexpr int64_t kFramePeriodUs = 33'333;

constexpr double kA4RadPerS = 0.5;
double a4_at(int64_t utime) {
  return test::side_reach_pose().at("a4") + kA4RadPerS * (utime - kStartUtime) * 1e-6;
}

class SchedulerTest : public ::testing::Test {
 protected:
  SchedulerTest()
      : config_(deployment::estimator_process_settings(test::sim_config())),
        scene_(load_estimator_scene(config_)),
        scheduler_(config_, scene_) {
    feed_joint_states(&scheduler_, /*a4_turning=*/true);
  }

  // Joint states every 10 ms over the whole test, a4 turning at kA4RadPerS
  // when `a4_turning`.
  void feed_joint_states(EstimatorScheduler* scheduler, bool a4_turning) const {
    for (int64_t t = kStartUtime - 100'000; t <= kStartUtime + 20 * kFramePeriodUs; t += 10'000) {
      joint_state_t s{};
      s.utime = t;
      s.robot_id = config_.robot.id;
      for (const auto& [name, position] : test::side_reach_pose()) {
        s.name.push_back(name);
        s.position.push_back(name == "a4" && a4_turning ? a4_at(t) : position);
        s.velocity.push_back(0);
      }
      s.num_joints = static_cast<int32_t>(s.name.size());
      EXPECT_TRUE(scheduler->on_joint_state(s));
    }
  }

  depth_image_t frame(int64_t seq) const {
    const Intrinsics& in = config_.camera.intrinsics;
    // Every pixel at 1000 + seq mm: tells the frames apart.
    const std::vector<float> depth_m(static_cast<size_t>(in.width) * in.height, (1000.0f + seq) / 1000.0f);
    return make_depth_image(config_.camera.id, in, kStartUtime + seq * kFramePeriodUs, seq, true, depth_m);
  }

  discrepancy_t discrepancy(int64_t seq, bool warning) const {
    discrepancy_t d{};
    d.utime = kStartUtime + seq * kFramePeriodUs;
    d.seq = seq;
    d.camera_id = config_.camera.id;
    d.usable = true;
    d.mismatch_fraction = warning ? 0.5 : 0.0;
    d.p95_abs_dis_mm = warning ? 200 : 5;
    return d;
  }

  // The seqs of the frames of the one job ready now (by their depth).
  std::vector<int> job_seqs() {
    std::vector<ScheduledWork> ready = scheduler_.take_ready();
    EXPECT_EQ(ready.size(), 1u);
    std::vector<int> seqs;
    if (ready.empty() || !ready[0].job) return seqs;
    for (const EstimatorFrame& f : ready[0].job->frames)
      seqs.push_back(static_cast<int>(std::lround(f.depth_m[0] * 1000)) - 1000);
    return seqs;
  }

  estimator::EstimatorProcessSettings config_;
  robot_model::SceneModel scene_;
  EstimatorScheduler scheduler_;
};

TEST_F(SchedulerTest, APeriodicEstimateTakesTheFramesJustBefore) {
  ASSERT_EQ(config_.estimator.frames_per_estimate, 3);
  for (int seq = 1; seq <= 5; ++seq) {
    ASSERT_TRUE(scheduler_.on_depth(frame(seq)));
    scheduler_.on_discrepancy(discrepancy(seq, false));
  }
  EXPECT_TRUE(scheduler_.take_ready().empty());
  scheduler_.request_newest();
  EXPECT_EQ(job_seqs(), (std::vector<int>{5, 4, 3}));
}

// The camera's profile (discrepancy.camera_profile) corrects the frames the
// estimator compares, as tofguard-discrepancy's; a frame it does not fit
// (another camera's intrinsics) is not estimated.
TEST_F(SchedulerTest, FramesAreCorrectedByTheCamerasProfile) {
  const Intrinsics& in = config_.camera.intrinsics;
  CameraProfile profile;
  profile.camera_id = config_.camera.id;
  profile.width = in.width;
  profile.height = in.height;
  profile.fx = in.fx;
  profile.fy = in.fy;
  profile.cx = in.cx;
  profile.cy = in.cy;
  profile.distance_correction_mm = {0.0};
  profile.pixel_correction_mm.assign(static_cast<size_t>(in.width) * in.height, 7.0f);
  config_.camera_profile = std::make_shared<const CameraProfile>(profile);
  EstimatorScheduler scheduler(config_, scene_);
  feed_joint_states(&scheduler, /*a4_turning=*/false);
  depth_image_t other = frame(1);
  other.fx += 1;
  EXPECT_FALSE(scheduler.on_depth(other));
  ASSERT_TRUE(scheduler.on_depth(frame(2)));
  scheduler.request_newest();
  const std::vector<ScheduledWork> ready = scheduler.take_ready();
  ASSERT_EQ(ready.size(), 1u);
  ASSERT_TRUE(ready[0].job);
  ASSERT_FALSE(ready[0].job->frames.empty());
  // Every pixel at 1002 mm, plus the profile's 7 mm.
  EXPECT_NEAR(ready[0].job->frames[0].depth_m[0], 1.009, 1e-6);
}

// A fault begins at frame 4: the first warning frame is estimated alone,
// the next with the warning frames before it, never with frames 1..3.
TEST_F(SchedulerTest, AWarningEstimateDoesNotTakeFramesFromBeforeTheFault) {
  for (int seq = 1; seq <= 3; ++seq) {
    ASSERT_TRUE(scheduler_.on_depth(frame(seq)));
    scheduler_.on_discrepancy(discrepancy(seq, false));
  }
  EXPECT_TRUE(scheduler_.take_ready().empty());
  ASSERT_TRUE(scheduler_.on_depth(frame(4)));
  scheduler_.on_discrepancy(discrepancy(4, true));
  EXPECT_EQ(job_seqs(), (std::vector<int>{4}));
  // (The default warning rate limit, 200 ms of camera time, lets the next
  // warning frame be estimated 7 frames later.)
  for (int seq = 5; seq <= 11; ++seq) {
    ASSERT_TRUE(scheduler_.on_depth(frame(seq)));
    scheduler_.on_discrepancy(discrepancy(seq, true));
  }
  EXPECT_EQ(job_seqs(), (std::vector<int>{11, 10, 9}));
  // Back to normal: a periodic estimate takes no warning frame.
  ASSERT_TRUE(scheduler_.on_depth(frame(12)));
  scheduler_.on_discrepancy(discrepancy(12, false));
  ASSERT_TRUE(scheduler_.on_depth(frame(13)));
  scheduler_.on_discrepancy(discrepancy(13, false));
  scheduler_.request_newest();
  EXPECT_EQ(job_seqs(), (std::vector<int>{13, 12}));
}

// tofguard-risk's published verdict triggers like a discrepancy past the
// warning level: a model mismatch on SAFETY_RISK gets its frame estimated
// (the discrepancy alone was below estimator.warning); a fault, a SAFE
// verdict or a timeout does not; a verdict about another utime is ignored.
risk_t verdict(int64_t seq, int8_t level, int8_t cause) {
  risk_t r{};
  r.utime = kStartUtime + seq * kFramePeriodUs;
  r.seq = seq;
  r.level = level;
  r.cause = cause;
  return r;
}

// With several cameras the published verdict is the worst camera's (its
// detail prefixed with its id): only this camera's verdicts trigger an
// estimate of this camera's frame of that seq.
TEST_F(SchedulerTest, WithSeveralCamerasOnlyThisCamerasVerdictTriggersAnEstimate) {
  EstimatorProcessSettings several = config_;
  several.several_cameras = true;
  EstimatorScheduler scheduler(several, scene_);
  feed_joint_states(&scheduler, /*a4_turning=*/true);
  for (int seq = 1; seq <= 3; ++seq) {
    ASSERT_TRUE(scheduler.on_depth(frame(seq)));
    scheduler.on_discrepancy(discrepancy(seq, false));
  }
  risk_t other = verdict(3, risk_t::DANGEROUS, risk_t::CAUSE_JOINT_ERROR);
  other.detail = "tof-side: joint a4 reads other than seen";
  scheduler.on_risk(other);
  EXPECT_TRUE(scheduler.take_ready().empty()) << "another camera's verdict triggered an estimate";
  risk_t own = other;
  own.detail = several.camera.id + ": joint a4 reads other than seen";
  scheduler.on_risk(own);
  const std::vector<ScheduledWork> ready = scheduler.take_ready();
  ASSERT_EQ(ready.size(), 1u);
  ASSERT_TRUE(ready[0].job.has_value());
  EXPECT_EQ(ready[0].job->context.seq, 3);
}

TEST_F(SchedulerTest, ARiskVerdictOfAModelMismatchTriggersAnEstimate) {
  for (int seq = 1; seq <= 3; ++seq) {
    ASSERT_TRUE(scheduler_.on_depth(frame(seq)));
    scheduler_.on_discrepancy(discrepancy(seq, false));
  }
  scheduler_.on_risk(verdict(1, risk_t::SAFE, risk_t::CAUSE_NONE));
  scheduler_.on_risk(verdict(2, risk_t::DANGEROUS, risk_t::CAUSE_SENSOR_FAULT));
  scheduler_.on_risk(verdict(-1, risk_t::DANGEROUS, risk_t::CAUSE_COMPONENT_FAULT));
  risk_t other_frame = verdict(3, risk_t::WARNING, risk_t::CAUSE_JOINT_ERROR);
  other_frame.utime += 1;
  scheduler_.on_risk(other_frame);
  EXPECT_TRUE(scheduler_.take_ready().empty());

  scheduler_.on_risk(verdict(3, risk_t::WARNING, risk_t::CAUSE_JOINT_ERROR));
  std::vector<ScheduledWork> ready = scheduler_.take_ready();
  ASSERT_EQ(ready.size(), 1u);
  ASSERT_TRUE(ready[0].job.has_value());
  EXPECT_EQ(ready[0].job->context.seq, 3);
  EXPECT_EQ(ready[0].job->context.trigger, motion_estimate_t::TRIGGER_WARNING);
  // A warning frame: estimated alone (frames 1, 2 are from before it).
  EXPECT_EQ(ready[0].job->frames.size(), 1u);
  // Once only.
  scheduler_.on_risk(verdict(3, risk_t::DANGEROUS, risk_t::CAUSE_JOINT_ERROR));
  EXPECT_TRUE(scheduler_.take_ready().empty());

  // A verdict before its frame (past the warning rate limit, 200 ms of
  // camera time): estimated when the frame comes, with the earlier warning
  // frame 3.
  scheduler_.on_risk(verdict(10, risk_t::WARNING, risk_t::CAUSE_UNKNOWN_OBJECT));
  EXPECT_TRUE(scheduler_.take_ready().empty());
  ASSERT_TRUE(scheduler_.on_depth(frame(10)));
  EXPECT_EQ(job_seqs(), (std::vector<int>{10, 3}));
}

// Each frame carries the joints interpolated at its own utime.
TEST_F(SchedulerTest, EachFrameHasItsOwnReportedJoints) {
  for (int seq = 1; seq <= 3; ++seq) ASSERT_TRUE(scheduler_.on_depth(frame(seq)));
  scheduler_.request_newest();
  std::vector<ScheduledWork> ready = scheduler_.take_ready();
  ASSERT_EQ(ready.size(), 1u);
  ASSERT_TRUE(ready[0].job.has_value());
  ASSERT_EQ(ready[0].job->frames.size(), 3u);
  int64_t seq = 3;
  for (const EstimatorFrame& f : ready[0].job->frames) {
    EXPECT_NEAR(f.reported_joints.at("a4"), a4_at(kStartUtime + seq-- * kFramePeriodUs), 1e-9);
    EXPECT_TRUE(f.world_from_optical.isApprox(test::pose_of(config_.camera.pose), 1e-9));
  }
}

}  // namespace
}  // namespace tofguard::estimator
