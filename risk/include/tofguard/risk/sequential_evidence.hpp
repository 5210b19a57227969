#pragma once
// Sequential evidence tests (docs/safety-chain.md, "Sequential evidence and
// its thresholds"): from the evidence fields of each discrepancy_t (a
// parameter's score s and information I: s ~ N(0, I) without a fault,
// s ~ N(I * delta, I) with the parameter off by delta), a per-frame
// log-likelihood ratio per hypothesis (the camera pose; each moving joint)
// and a CUSUM on it, S_k = max(0, S_{k-1} + LLR_k), capped at h. A
// hypothesis crosses when S_k >= h; h follows from the target false-stop
// rate (Lorden's bound and a union bound over the hypotheses). Pure logic:
// frames come in frame order, no clocks, no LCM.
#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

// A drift of the camera's distances since commissioning against a moved
// camera (docs/safety-chain.md, "A drift of the camera's distances"), from
// a frame's camera fit and its common distance offset
// (discrepancy_t.distance_offset_*): the chi-squares the fit of both
// together explains beyond each alone. A drift when the offset explains
// more than `threshold_chi2` beyond the pose and the pose no more than that
// beyond the offset.
struct DistanceDrift {
  bool drift = false;
  double offset_mm = 0;  // the camera reads this much farther (mm, along each ray)
  double offset_sigma_mm = 0;
  double offset_beyond_pose_chi2 = 0;
  double pose_beyond_offset_chi2 = 0;
};
DistanceDrift distance_drift(const discrepancy_t& frame, double threshold_chi2);

// log(cosh(x)), stable for any finite x: |x| + log1p(exp(-2|x|)) - log 2.
double log_cosh(double x);

// The per-frame log-likelihood ratio of "the parameter is off by +delta or
// -delta (1/2 each)" against "it is not", for score s and information I:
// log cosh(delta s) - delta^2 I / 2.
double joint_llr(double score, double information, double delta);
// The alternative a shrunk score is tested against (docs/safety-chain.md,
// "Static error: the composite null"): a fault of delta moves the plain
// score by delta * information, the shrunk one by that less the static
// bound, i.e. as a fault of delta - bound / information (>= 0; 0: the fault
// cannot show beyond the allowance, the ratio is 1). With no bound: delta.
double effective_delta(double delta, double information, double static_bound);
// The smallest offset (radians, or metres for a prismatic joint) whose
// stop test gains evidence on one frame, on average (docs/safety-chain.md,
// "The smallest fault a frame can show"): a fault of theta moves the
// shrunk score by theta * I - B, and the simple alternative's expected
// ratio d' (theta I - B) - d'^2 I / 2, d' = effective_delta, beats the
// memory decay when
//   theta > B / I + d' / 2 + decay / (d' I).
// Infinity when d' is 0 (the allowance covers the whole alternative) or
// the frame has no information. The mixture's log 2 per frame is left out,
// so this is the offset's lower bound: a smaller fault's test only falls.
double smallest_growing_offset(double delta, double information, double static_bound, double memory_decay);

// The camera's: the mixture over the 12 alternatives "+-delta_a along
// parameter a" (tx, ty, tz, rx, ry, rz), with the diagonal of the 6x6
// information matrix (row-major): log((1/6) sum_a cosh(delta_a s_a)
// exp(-delta_a^2 I_aa / 2)), by log-sum-exp.
double camera_llr(const std::array<double, 6>& score, const std::array<double, 36>& information,
                  const std::array<double, 6>& delta);

// A region of the camera fit (discrepancy_t.camera_region_*) votes in the
// camera test when one frame of it alone carries at least this much
// evidence at the test's delta, nats: max_a delta_a^2 I_aa / 2 >= 1. A
// region with less can neither show nor rule out a pose error of the
// test's size; its vote would only hold the others back.
constexpr double kCameraRegionVoteNats = 1.0;

// Whether a region with this information diagonal (6 entries) votes.
bool camera_region_votes(const double* information_diagonal, const std::array<double, 6>& delta);

struct CameraRegionRatio {
  // The camera test's per-frame log-likelihood ratio.
  double llr = 0;
  // How many regions voted, and how many had to agree (0 when none voted
  // and llr is the whole image's camera_llr).
  int voters = 0;
  int agree = 0;
};

// The camera test's per-frame ratio from the image regions: a pose error
// moves the whole static scene, an object flush with a modelled surface
// one region. Of the n regions that vote, the m-th largest camera_llr,
// m = min(n, 3), minus log(n / m) (so that E_0[LR] <= 1 still holds: the
// m-th largest LR is at most the mean of the m largest); with no region
// voting, the whole image's camera_llr. docs/safety-chain.md, "Sequential
// evidence and its thresholds". `alternative_fraction` scales the
// alternatives the ratio is computed at (each axis's effective delta),
// not the regions' votes: the clearing test's ratio at half of them.
CameraRegionRatio camera_region_llr(const discrepancy_t& frame, const std::array<double, 6>& delta,
                                    double alternative_fraction = 1.0);

// The clearing test's alternative as a fraction of the stop test's
// (docs/safety-chain.md, "How long a diagnosis stays open"): a diagnosis
// closes only on evidence that the fault is smaller than half of what the
// stop test looks for. The stop test's ratio turns against a fault read
// below delta/2, so a large fault that the linear fit reads smaller as
// the arm moves (a6 3 deg off read as 1-2.5 deg) looks like no fault to
// it; the clearing test's turns against it only below delta/4.
constexpr double kClearingAlternativeFraction = 0.5;

// How long a stop test remembers, in seconds of frames: every test's
// per-frame ratio is lowered by h / (camera rate * kEvidenceMemoryS) nats
// (SequentialEvidence::memory_decay), so a CUSUM at h with nothing behind
// it falls to 0 within this time. Without it a hypothesis that frames
// hardly inform (a joint seen over a few pixels, or one whose fault cannot
// show beyond the static allowance: effective delta 0) keeps what earlier
// frames gave it: the mixture's drift under no fault is -(delta^2 I)^2 / 4
// per frame, so a CUSUM at the warning level stays there for hours and no
// reset is accepted. The price: a fault whose test would need more than
// this long to cross is not found by it, and one that needs t seconds needs
// t / (1 - t / kEvidenceMemoryS) (docs/safety-chain.md, "A bounded memory").
constexpr double kEvidenceMemoryS = 60.0;

// The CUSUM threshold for `hypotheses` tests on frames at `rate_hz` and at
// most one false stop per `false_stop_period_h` hours:
// h = ln(hypotheses * rate_hz * 3600 * false_stop_period_h).
double cusum_threshold(int hypotheses, double rate_hz, double false_stop_period_h);

// Several cameras (docs/safety-chain.md, "Several cameras: joint evidence
// summed"): each camera's own tests and the joints' tests pooled over
// every camera's frames are `cameras` + 1 families of tests, each held to
// one false stop in (`cameras` + 1) * evidence_false_stop_period_h hours,
// so that the deployment keeps one in evidence_false_stop_period_h. The
// settings each family's tests are made with: `risk` as it is for one
// camera.
RiskSettings several_cameras_evidence_settings(const RiskSettings& risk, size_t cameras);

// Whether `frame` carries the naming search (discrepancy_t.joint_search_*,
// one entry per joint).
bool searched(const discrepancy_t& frame);

// How much of frame's residual an offset of joint `index` explains, chi^2:
// the naming search's gain when the frame carries it, else the linear
// naming fit's s^2 / I (0 without information).
double naming_chi2(const discrepancy_t& frame, int index);

// The naming search's camera candidate (discrepancy_t.camera_search_*)
// against its joints: the camera move's gain less the best joint's, chi^2
// (-infinity when the frame carries no camera candidate).
double camera_beyond_joints_chi2(const discrepancy_t& frame);

// What one frame's evidence says.
struct EvidenceStep {
  // The frame carried evidence (discrepancy_t.evidence_available) and the
  // CUSUMs were updated.
  bool updated = false;
  // A hypothesis crossed h (finding: its cause, suspect and detail; score
  // its CUSUM, threshold h).
  bool crossed = false;
  // No crossing, but a CUSUM at or above warning_fraction * h (finding:
  // the largest one's).
  bool warning = false;
  FrameFinding finding;
  // Every CUSUM below warning_fraction * h after this frame.
  bool quiet = true;
  // One line with the frame's evidence: the largest CUSUM and h.
  std::string summary;
};

class SequentialEvidence {
 public:
  // The hypotheses: the camera and each of `robot`'s moving joints (their
  // offsets in radians, prismatic joints in metres). `camera_rate_hz`:
  // camera.rate_hz (> 0), the rate frames come at. `camera_test` false:
  // the joints' tests alone (the tests pooled over several cameras' frames,
  // whose poses are tested each on its own: pooled_evidence_settings).
  SequentialEvidence(const RiskSettings& risk, const robot_model::KinematicTree& robot, double camera_rate_hz,
                     bool camera_test = true);

  // The next frame in frame order. A frame without evidence changes
  // nothing (updated false; quiet tells the CUSUMs' state).
  EvidenceStep update(const discrepancy_t& frame);
  // Every CUSUM and clearing test back to 0 (a closed diagnosis).
  void reset();

  double threshold() const { return h_; }
  double warning_level() const { return warning_fraction_ * h_; }
  // The level a clearing test must reach: h, as a stop test's
  // (docs/safety-chain.md, "How long a diagnosis stays open").
  double clearing_level() const { return h_; }
  // The stop tests the threshold's union bound counts: the camera's and
  // each joint's two (at joint_offset and at large_joint_offset).
  int hypotheses() const { return 2 * static_cast<int>(joint_tests_.size()) + (camera_test_ ? 1 : 0); }
  // What every stop test's per-frame ratio is lowered by, nats:
  // h / (camera rate * kEvidenceMemoryS).
  double memory_decay() const { return memory_decay_; }
  double camera_cusum() const { return camera_cusum_; }
  // A joint's stop tests: the larger of its two CUSUMs; 0 for a joint that
  // is not a moving joint of the robot.
  double joint_cusum(const std::string& joint) const;
  // Its large-offset test's CUSUM alone (0 for one that is not a moving joint).
  double joint_large_cusum(const std::string& joint) const;
  // Every CUSUM below warning_level().
  bool quiet() const;
  // The smallest offset of joint `index` of `frame` that its stop tests gain
  // evidence of on that frame, on average: smallest_growing_offset of the
  // frame's information and static bound at each test's alternative, the
  // smaller (radians, metres for a prismatic joint; infinity when neither
  // can show one).
  double smallest_offset(const discrepancy_t& frame, int index) const;
  // A joint's two alternatives as configured (radians; metres for a
  // prismatic joint), before the allowance takes its share: the first
  // test's (evidence.joint_offset) and the large-offset test's.
  struct JointAlternatives {
    double first;
    double large;
  };
  JointAlternatives joint_alternatives(const std::string& joint) const;
  // Hypothesis `hypothesis` ("camera" or a joint) shows evidence that its
  // fault is gone: its clearing test, a CUSUM on the negated log-likelihood
  // ratio at kClearingAlternativeFraction of the stop test's (effective)
  // delta, restarted at each crossing of its stop test, is at
  // clearing_level(). True for a name that is not a hypothesis.
  bool cleared(const std::string& hypothesis) const;
  // The clearing test of a hypothesis ("camera" or a joint): 0 for one that
  // is not a hypothesis.
  double clearing_cusum(const std::string& hypothesis) const;
  // One line on hypothesis's clearing test.
  std::string clearing_summary(const std::string& hypothesis) const;

 private:
  // A joint's two stop tests (docs/safety-chain.md, "A large offset"): at
  // the smallest fault to detect (evidence.joint_offset), and at a large
  // offset (evidence.large_joint_offset), which still shows where the static
  // allowance covers the first test's whole alternative.
  struct JointTests {
    double at_delta = 0;
    double at_large = 0;
    // The last crossing was the large-offset test's alone: the clearing test runs
    // at half of the large alternative (at half of the first test's, where
    // the allowance covers it, it could never clear).
    bool clearing_at_large = false;
    double largest() const { return at_delta > at_large ? at_delta : at_large; }
  };

  // A hypothesis's name ("camera" or a joint's) and its CUSUM.
  struct NamedCusum {
    std::string name;
    double value;
  };

  // A frame's log-likelihood ratios into the CUSUMs and the clearing tests.
  void add_frame(const discrepancy_t& frame);
  // Joint `index` of the frame into its tests and its clearing test.
  void add_joint(const discrepancy_t& frame, int index, JointTests* tests);
  // The largest CUSUM (the camera's among equals).
  NamedCusum largest_cusum() const;
  // The joint test that crossed with the largest CUSUM (name empty: none).
  NamedCusum crossed_joint() const;
  // The index of the joint the stop names (-1: none explains the frame
  // well enough). Which one: the joint whose offset explains this frame's
  // residual best (naming_chi2: the naming search's gain, discrepancy_t.
  // joint_search_*, else the linear naming fit's s^2 / I), among every
  // joint of the robot (the first test to cross may be a distal joint's,
  // whose links the true joint's offset moves furthest); a joint whose own
  // test has not crossed only on strong evidence of this frame alone (2h
  // more than the best crossed joint explains), so that a weak fault's
  // neighbours' noise does not name them. Measured on three arms:
  // docs/safety-chain.md, "Measured".
  int suspect_joint(const discrepancy_t& frame) const;
  // The finding of a stop for a joint: `crossed` is the joint test that
  // crossed.
  FrameFinding joint_stop_finding(const discrepancy_t& frame, const NamedCusum& crossed) const;
  // The finding of a stop a joint's test crossed for when the naming
  // search's camera move explains the frame 2h better than any joint's
  // offset (a camera moved sideways moves the arm as a base joint does, and
  // the arm's edges cross a joint's test before the scene's slopes cross
  // the camera's): a calibration error; the test that crossed stays the
  // diagnosis's (FrameFinding::crossed_test).
  FrameFinding search_camera_finding(const discrepancy_t& frame, const NamedCusum& crossed) const;
  // The finding of a warning for the `largest` CUSUM.
  FrameFinding warning_finding(const discrepancy_t& frame, const NamedCusum& largest) const;
  FrameFinding camera_finding(const discrepancy_t& frame) const;
  // The camera test's finding when a drift of the camera's distances
  // explains the frame (distance_drift), not a moved camera.
  FrameFinding drift_finding(const DistanceDrift& drift) const;
  FrameFinding joint_finding(const discrepancy_t& frame, int index) const;

  bool camera_test_;
  std::set<std::string> prismatic_;
  double joint_delta_rad_;
  double joint_delta_m_;
  double joint_large_rad_;
  double joint_large_m_;
  std::array<double, 6> camera_delta_;
  double warning_fraction_;
  double h_;
  double memory_decay_;
  double camera_cusum_ = 0;
  std::map<std::string, JointTests> joint_tests_;  // every moving joint of the robot
  // The clearing tests: "camera" and every moving joint.
  std::map<std::string, double> clearing_cusum_;
};

}  // namespace tofguard::risk
