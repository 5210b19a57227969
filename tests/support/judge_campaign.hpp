#pragma once
// The judgement campaign (issue 14): the observer chain's judgement
// (renderer -> discrepancy -> risk) run in-process, frame by frame, on
// simulated camera frames of an arm with injected faults, without LCM or
// clocks, so that thousands of frames are judged in minutes and every
// figure (detection, cause, suspect at the stop, latency in frames, SAFE
// verdicts while the fault persists, false stops) is counted exactly.
//
// What is real: the URDF and meshes, the EGL renderer (truth and model),
// the simulated ToF camera's error model and the config's distance
// calibration, compute_discrepancy and RiskMonitor with the config's
// settings. What is not: the transport (frames are paired by hand), the
// deadlines (every input is fresh), the estimator and the plan (off; they
// are tested on their own).
//
// Arms: the default (config/sim.yaml as it is), and any URDF with a generic
// scene: a floor and a back wall as the environment, the camera 1.5-1.7 m
// away looking down at the arm, every actuated joint moving about a bent
// pose. Frames: camera optical (x right, y down, z forward); world = the
// robot's root link.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/deployment/config.hpp"

namespace tofguard::test {

// One arm's scene: the config (robot, environment, camera, settings) and
// each actuated joint's motion (joints_sim.motion's convention).
struct CampaignArm {
  std::string name;
  deployment::Config config;
};

// The default arm: config/sim.yaml (its motion and camera) as it is.
CampaignArm default_campaign_arm();
// `urdf` with package paths, in the generic scene written under
// `scene_dir`; the camera at `eye_m` looking at `target_m` (world, m).
CampaignArm generic_campaign_arm(const std::string& name, const std::string& urdf,
                                 const std::vector<std::string>& package_paths, const std::string& scene_dir,
                                 const Eigen::Vector3d& eye_m, const Eigen::Vector3d& target_m);
// The iiwa14 and the Kinova Gen3 7-DOF from `shared_dir` (../shared), or
// nothing when their files are absent.
std::optional<CampaignArm> iiwa14_campaign_arm(const std::string& shared_dir, const std::string& scene_dir);
std::optional<CampaignArm> kinova_gen3_campaign_arm(const std::string& shared_dir,
                                                    const std::string& scene_dir);

// A fault from frame `onset_frame` on (none: kind kNone).
struct CampaignFault {
  enum class Kind { kNone, kJointOffset, kCameraPose };
  Kind kind = Kind::kNone;
  // kJointOffset: the joint reports `offset` (rad; m prismatic) more than
  // its true position.
  std::string joint;
  double offset = 0;
  // kCameraPose: the camera really is at reported * error (error in the
  // reported optical frame), while the renderer keeps the reported pose.
  Eigen::Isometry3d camera_error = Eigen::Isometry3d::Identity();
  std::string label;  // for the report, e.g. "a4 +3 deg"
};

struct CampaignRun {
  CampaignFault fault;
  int onset_frame = 20;
  int frames_after_onset = 45;
  // Motion time of frame 0, seconds (varies the pose between runs).
  double start_s = 0;
  uint64_t noise_seed = 0;
};

// What happened in one run.
struct CampaignResult {
  std::string label;
  // A DANGEROUS verdict before the onset (a false stop), its detail.
  bool false_stop = false;
  std::string false_stop_detail;
  // The first DANGEROUS verdict at or after the onset.
  bool stopped = false;
  int stop_frames = 0;  // frames from onset to the stop, the onset frame counted as 1
  int8_t cause = 0;
  std::string suspect;
  std::string detail;
  bool right_cause = false;    // the fault's cause (and joint)
  bool right_suspect = false;  // joint faults: the suspect is the joint
  // After the stop, while the fault persists.
  int safe_after_stop = 0;
  int suspect_changes = 0;
  int frames_judged = 0;
  // At the onset, without camera noise: pixels whose depth the fault
  // changes by more than 3 sigma of the camera's noise (the model rendered
  // at the true and at the reported joints and pose). A fault that changes
  // no pixel cannot be seen by any camera rule.
  int changed_pixels = 0;
  // Before the onset (nominal frames): the standardised scores
  // t = s / sqrt(I) of every joint and camera parameter with information,
  // which the sequential tests take to be N(0, 1) without a fault
  // (docs/safety-chain.md): how many, their sum of squares, how many beyond
  // 4 (N(0,1): 6.3e-5) and the largest |t|.
  int64_t nominal_scores = 0;
  double nominal_score_sum_sq = 0;
  int64_t nominal_scores_beyond_4 = 0;
  double nominal_score_max_abs = 0;
  // Half the mean square of frame-to-frame differences of each joint's t:
  // the noise's share of the variance (a bias that changes slowly with the
  // pose cancels in the difference).
  int64_t nominal_differences = 0;
  double nominal_difference_sum_sq = 0;
};

// Runs `runs` on `arm`, each from a fresh chain (new CUSUMs, new latch).
// Throws std::runtime_error when the scene cannot be loaded or rendered.
std::vector<CampaignResult> run_campaign(const CampaignArm& arm, const std::vector<CampaignRun>& runs);

// The fault set of issue 14's targets on `arm`: every actuated joint at
// each of `joint_offsets_deg` (signs alternating), the camera moved by 2 cm
// along x, y, z and 3 cm along z, and turned 1 degree about x, y, z.
std::vector<CampaignRun> standard_fault_runs(const CampaignArm& arm,
                                             const std::vector<double>& joint_offsets_deg);

// Nominal: `seconds` of frames without a fault, split into runs of `run_s`.
std::vector<CampaignRun> nominal_runs(double seconds, double run_s, uint64_t seed);

// A markdown table of `results` per fault kind and a line per run that
// missed a target.
std::string campaign_report(const std::string& arm, const std::vector<CampaignResult>& results,
                            double frame_period_s);

}  // namespace tofguard::test
