#pragma once
// The estimate gate (docs/safety-chain.md, "Using the motion estimate"):
// frames pass through it in arrival order, classified once on arrival. With
// risk.estimate.enabled, a frame whose frame-rule finding is a model mismatch
// waits at most risk.estimate.wait_ms (tofguard-risk's monotonic clock, from
// its arrival) for the estimate of its seq; frames behind it wait with it,
// so verdicts keep frame order and the debounce counts frames in order.
//
// On release the estimate (the frame's own, else the newest of an earlier
// frame of the same camera at most risk.estimate.max_age_ms older in camera
// utime) may rename the mismatch's cause, suspect and detail. Fail safe: it
// replaces one finding by another, never by "safe"; without one the frame
// rules' finding stands.
#include <cstdint>
#include <deque>
#include <set>
#include <string>
#include <vector>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

// A frame classified on arrival, with the joint state of its capture time.
struct ClassifiedFrame {
  discrepancy_t frame;
  // The frame rules' finding; when they find nothing, the plan rule's.
  FrameFinding finding;
  // The frame rules found a model mismatch (is_model_mismatch): a cause an
  // estimate may rename. The plan rule's finding is not one (the camera saw
  // nothing wrong).
  bool model_mismatch = false;
};

class EstimateGate {
 public:
  // risk.estimate and the thresholds classify_estimate uses;
  // `prismatic_joints` (offsets in metres, all others radians).
  EstimateGate(const RiskSettings& risk, std::set<std::string> prismatic_joints);

  // A frame arrives at monotonic `now_us`: the frames released now, in
  // arrival order, with their final findings.
  std::vector<ClassifiedFrame> admit(ClassifiedFrame frame, int64_t now_us);
  // A valid estimate (check_motion_estimate, this camera, the robot's
  // joints): the frames it releases.
  std::vector<ClassifiedFrame> add_estimate(const motion_estimate_t& estimate, int64_t now_us);
  // The frames whose wait has ended by `now_us`.
  std::vector<ClassifiedFrame> release_due(int64_t now_us);
  size_t waiting_frames() const { return waiting_.size(); }

  struct Stats {
    int64_t received = 0;
    int64_t used = 0;               // named a frame's cause
    int64_t explained_nothing = 0;  // there, but no finding (the frame rules judged)
    int64_t missing = 0;            // a waiting frame's wait ended without its own
    int64_t late = 0;               // arrived after its frame's wait had ended without it
  };
  const Stats& stats() const { return stats_; }

 private:
  struct WaitingFrame {
    ClassifiedFrame classified;
    int64_t wait_until_us = 0;  // monotonic
  };
  bool waits(const ClassifiedFrame& c) const { return enabled_ && c.model_mismatch; }
  // The estimate of `frame` itself; with or_older, else the newest of an
  // earlier frame of the same camera at most max_age_us older.
  const motion_estimate_t* estimate_for(const discrepancy_t& frame, bool or_older) const;
  // The estimate's finding replaces a waiting frame's model mismatch.
  void rename_cause(ClassifiedFrame* c);
  std::vector<ClassifiedFrame> release(int64_t now_us);

  const RiskSettings risk_;  // classify_estimate's thresholds
  std::set<std::string> prismatic_joints_;
  bool enabled_;
  int64_t wait_us_;
  int64_t max_age_us_;
  std::deque<WaitingFrame> waiting_;
  std::deque<motion_estimate_t> estimates_;  // the newest few, by arrival
  std::deque<int64_t> missed_seqs_;          // the newest few frames judged without their own estimate
  Stats stats_;
};

}  // namespace tofguard::risk
