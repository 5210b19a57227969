#pragma once
// The judgement campaign: the observer chain's judgement
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
#include <map>
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
// The two-camera scene: config/sim-two-cameras.yaml as it is, both its
// simulated cameras imperfect as real ones and commissioned. Each camera's
// frame is judged by its own discrepancy (the other's frame its witness)
// and one judgement of both, as tofguard-risk judges them.
CampaignArm two_camera_campaign_arm();
// Camera `camera_id` of a deployment of several cameras as a deployment of
// its own (its lone camera, its profile, one camera's thresholds).
CampaignArm camera_alone(const CampaignArm& arm, const std::string& camera_id);
// `arm` (one camera) watched by a second camera as well: its own, turned by
// `turn_deg` about the world's vertical through the robot's root, with the
// same sensor, judged together as config/sim-two-cameras.yaml's cameras are.
CampaignArm with_second_camera(const CampaignArm& arm, double turn_deg);
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

// `arm` watched by a camera at `rate_hz` (camera.rate_hz: the evidence
// tests' threshold and the protective field's response time follow it;
// every camera's, with several).
CampaignArm with_camera_rate(const CampaignArm& arm, double rate_hz);
// `arm` watched from a second placement: its camera pose turned by
// `turn_deg` about the world's vertical (z) axis through the robot's root
// (the world origin), so the camera sees the arm from another side (every
// camera, with several).
CampaignArm with_camera_turned(const CampaignArm& arm, double turn_deg);

// A fault from frame `onset_frame` on (none: kind kNone).
struct CampaignFault {
  // kFrozenImage: from the onset the camera repeats the image before it,
  // byte for byte (a frozen driver), while the joints go on moving.
  // kCameraStall / kJointStall: from the onset no depth frame / no joint
  // state arrives (the monitor's input deadlines; the frames judged are
  // the ones still arriving).
  enum class Kind { kNone, kJointOffset, kCameraPose, kObject, kFrozenImage, kCameraStall, kJointStall };
  Kind kind = Kind::kNone;
  // With several cameras: the camera (index in config.cameras) that a
  // camera fault (pose, frozen image, stall) is in; objects and joint
  // faults are seen by every camera.
  size_t camera = 0;
  // The fault's kind and size for the report and the plots (e.g. "joint
  // offset", 5 (deg); "camera translation", 2 (cm)); size 0: no size.
  std::string group;
  double magnitude = 0;
  // kJointOffset: the joint reports `offset` (rad; m prismatic) more than
  // its true position.
  std::string joint;
  double offset = 0;
  // kCameraPose: the camera really is at reported * error (error in the
  // reported optical frame), while the renderer keeps the reported pose.
  Eigen::Isometry3d camera_error = Eigen::Isometry3d::Identity();
  // kObject: a box of object_size_m (edges along the world's axes) that
  // the camera sees and the model does not, placed at the onset so that
  // its nearest point is object_distance_m from the arm's surface (the
  // arm's cover of 1 cm cells at the onset's true joints: within 3 cm of
  // the true surface), beside the arm's farthest point from its root, on
  // the image's right (object_side +1) or left (-1). From then on it moves
  // at object_speed_m_s: straight at that point (object_approaches), else
  // horizontally across the line to it (a person or cart walking past).
  // object_in_field: whether it is meant to be stopped (inside the
  // protective field) or not (a stop is then a false stop).
  Eigen::Vector3d object_size_m = Eigen::Vector3d::Constant(0.1);
  double object_distance_m = 0;
  int object_side = 1;
  double object_speed_m_s = 0;
  bool object_approaches = false;
  bool object_in_field = true;
  std::string label;  // for the report, e.g. "a4 +3 deg"
};

struct CampaignRun {
  CampaignFault fault;
  int onset_frame = 20;
  int frames_after_onset = 45;
  // Motion time of frame 0, seconds (varies the pose between runs).
  double start_s = 0;
  uint64_t noise_seed = 0;
  // Besides the fault, from frame 0 on: a still cube of edge
  // occluder_size_m (0: none) centred at occluder_centre_m (world, m), e.g.
  // before a camera (occluder_before), hiding part of its view of the arm
  // (a harmless object between that camera and the arm).
  double occluder_size_m = 0;
  Eigen::Vector3d occluder_centre_m = Eigen::Vector3d::Zero();
};

// The point `distance_m` along camera `camera_id`'s optical axis (world, m).
Eigen::Vector3d occluder_before(const CampaignArm& arm, const std::string& camera_id, double distance_m);

// What happened in one run.
struct CampaignResult {
  std::string label;
  std::string group;  // CampaignFault::group, magnitude
  double magnitude = 0;
  // A DANGEROUS verdict before the onset (a false stop), its detail.
  bool false_stop = false;
  std::string false_stop_detail;
  // The first DANGEROUS verdict at or after the onset.
  bool stopped = false;
  int stop_frames = 0;  // frames from onset to the stop, the onset frame counted as 1
  // Time from the onset (the capture time of the first faulty frame, or
  // the time the first missing message was due) to the stop's verdict, on
  // the campaign's clock (one frame period a frame; no transport).
  double stop_latency_s = 0;
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
  // A joint offset fault: the naming search's gain of the faulty joint
  // (discrepancy_t.joint_search_gain, chi^2) on each frame from the onset.
  std::vector<double> fault_search_gain;
  // kObject: pixels where the camera sees the object at the onset; its true
  // distance to the arm (the 1 cm cover) at the onset, the least over the
  // run, and at the stop's frame; the stop's score and threshold (for an
  // unknown object: its distance and S, m); WARNING verdicts after the
  // onset.
  int object_pixels = 0;
  // Its true distance when the camera first saw it (>= 20 px), -1: never.
  double object_first_seen_m = -1;
  double object_distance_at_onset_m = 0;
  double object_min_distance_m = 0;
  double object_distance_at_stop_m = 0;
  double stop_score = 0;
  double stop_threshold = 0;
  int warnings_after_onset = 0;
  // Whether the fault should stop the arm (false for nominal runs and
  // objects outside the protective field).
  bool expected_stop = false;
  bool object = false;
  bool approaching = false;
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
  // On the nominal frames of a run without a fault: per joint, the
  // smallest offset each frame can show (risk::smallest_growing_offset;
  // degrees, or mm for a prismatic joint; infinity where the allowance
  // covers the whole alternative).
  std::map<std::string, std::vector<float>> nominal_smallest_offset;
  // On the same frames, per joint: the naming search's gain (chi^2), and
  // the gains of the frames whose searched offset is at least the
  // large-offset test's alternative (evidence.large_joint_offset).
  std::map<std::string, std::vector<double>> nominal_search_gain;
  std::map<std::string, std::vector<double>> nominal_search_gain_large;
};

// Runs `runs` on `arm`, each from a fresh chain (new CUSUMs, new latch).
// Throws std::runtime_error when the scene cannot be loaded or rendered.
std::vector<CampaignResult> run_campaign(const CampaignArm& arm, const std::vector<CampaignRun>& runs);

// The detection matrix's faults (docs/detection.md): every actuated joint at each of `joint_offsets_deg`;
// the camera moved by each of `camera_translations_cm` along its optical
// x, y and z (the optical axis) and turned by each of
// `camera_rotations_deg` about x, y and z (signs alternating).
struct FaultMagnitudes {
  std::vector<double> joint_offsets_deg;
  std::vector<double> camera_translations_cm;
  std::vector<double> camera_rotations_deg;
};
std::vector<CampaignRun> fault_runs(const CampaignArm& arm, const FaultMagnitudes& magnitudes);

// Streams that stop or freeze: the camera repeating its image, the camera
// stream stalled and the joint stream stalled, `runs_each` runs each.
std::vector<CampaignRun> stream_fault_runs(int runs_each);

// The detection matrix's objects on `arm`: a 10 cm cube held still beside the arm at
// each of `distances_m`; a hand-sized box (10 x 10 x 20 cm) approaching
// at K = risk.field.approach_speed_m_s from beyond the warning field; and
// a person (0.4 x 0.3 x 1.7 m) and a cart (0.6 x 0.4 x 0.8 m) walking past
// at 1 m/s, `beyond_m` beyond the warning field of the arm at rest.
std::vector<CampaignRun> object_runs(const CampaignArm& arm, const std::vector<double>& distances_m,
                                     double beyond_m);

// Nominal: `seconds` of frames at `rate_hz` without a fault, split into
// runs of `run_s`.
std::vector<CampaignRun> nominal_runs(double seconds, double run_s, double rate_hz, uint64_t seed);

// People and carts walking past beyond the warning field of the arm at
// rest, one after another, for `seconds` in all (the false-stop
// target: they may warn, never stop).
std::vector<CampaignRun> passer_runs(const CampaignArm& arm, double seconds, uint64_t seed);

// A markdown table of the object runs of `results` per kind:
// runs, the object's pixels and distances, detection, latency, the
// distance at the stop and S, warnings and false stops; and a line per run
// that missed a target (an object in the field not stopped, or stopped
// only nearer than risk.field.intrusion_distance_m plus what K covers in
// the chain's latency and the robot's stop; an object outside stopped).
std::string object_report(const std::string& arm, const std::vector<CampaignResult>& results,
                          const deployment::Config& config);

// A markdown table of `results` (object runs left out) per fault kind and a
// line per run that missed a target; "" when there are none.
std::string campaign_report(const std::string& arm, const std::vector<CampaignResult>& results,
                            double frame_period_s);

// One tab-separated line per run (arm with its rate and placement, group,
// magnitude, unit, label, expected stop, stopped, right cause, right
// suspect, latency from onset in ms, false stop, frames judged, pixels the
// fault changed), after a header line when `header`.
std::string campaign_tsv(const std::string& arm, const std::vector<CampaignResult>& results, bool header);

// PNG plots from campaign_tsv's lines: per fault group with a magnitude and
// robot (the arm's name before ", "), the detection rate and the median and
// p99 latency (ms) against the magnitude, a curve per rate and placement.
// Writes <dir>/detection-<group>-<robot>.png (lower case, '-' for spaces)
// and returns the paths. Throws std::runtime_error when a file cannot be written.
std::vector<std::string> plot_campaign(const std::string& csv_text, const std::string& dir);

}  // namespace tofguard::test
