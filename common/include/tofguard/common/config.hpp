#pragma once
// The deployment config: one YAML file per deployment (config/sim.yaml is the
// embedded default). Every process loads and validates the whole file at
// start, so that a config error stops every process the same way, with one
// line naming the file, the key and what was expected (ConfigError, exit
// code 2), before anything is published.
//
// Units are in the names: _m metres, _ms milliseconds, _hz hertz, _mm
// millimetres. Relative paths are resolved against the config file's folder.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/common/config_error.hpp"

namespace tofguard {

// Where the messages go. Small safety messages and depth images travel on
// different multicast ports, so that a watchdog's socket is never flooded by
// depth frames.
struct LcmConfig {
  // Safety messages (joint state, risk, status, heartbeats...).
  std::string url;
  // Image channels (TOF_DEPTH, TOF_RENDERED, TOF_LABELS); needs a receive
  // buffer big enough for a whole frame.
  std::string image_url;
};

// Channel names; each may be renamed in the config's `channels` section.
struct ChannelNames {
  std::string depth = "TOF_DEPTH";
  std::string joint_state = "JOINT_STATE";
  std::string camera_pose = "CAMERA_POSE";
  std::string rendered = "TOF_RENDERED";
  std::string labels = "TOF_LABELS";
  std::string discrepancy = "SAFETY_DISCREPANCY";
  std::string risk = "SAFETY_RISK";
  std::string status = "SAFETY_STATUS";
  std::string reset = "SAFETY_RESET";
  std::string reset_reply = "SAFETY_RESET_REPLY";
  std::string heartbeat = "SAFETY_HEARTBEAT";
  // The power-cut actuator `lcm` (power_relay_t, positive logic).
  std::string power = "SAFETY_POWER";
  // tofguard-estimator's joint offsets and camera correction
  // (motion_estimate_t) and the arm controller's plan (planned_trajectory_t).
  std::string motion_estimate = "MOTION_ESTIMATE";
  std::string planned_trajectory = "PLANNED_TRAJECTORY";
  // Simulation only: the simulated arm's true joint state (for the simulated
  // camera) and run-time encoder fault injection.
  std::string sim_true_joint_state = "SIM_TRUE_JOINT_STATE";
  std::string sim_joint_fault = "SIM_JOINT_FAULT";
  // Simulation only: run-time fault injection into the simulated camera.
  std::string sim_camera_fault = "SIM_CAMERA_FAULT";
};

struct RobotConfig {
  std::string id;
  std::string urdf_path;
  // Folders searched for package://NAME/... mesh URIs: NAME is looked up as
  // a sub-folder of each.
  std::vector<std::string> package_paths;
};

struct EnvironmentConfig {
  // Static-environment URDFs (fixed joints only), placed in the same world
  // frame as the robot's root link.
  std::vector<std::string> urdf_paths;
};

// Distance calibration applied by tofguard-camera before publishing:
//   d_calibrated = d - p(d),  p(d) = sum_i coefficients_m[i] * d^i,
// with d the measured distance along the pixel's ray (radial, not Z) in
// metres and p(d) in metres; a Z image is corrected per pixel through its
// ray (camera/include/tofguard/camera/depth_calibration.hpp). Fitted by
// tofguard-calibrate-depth.
struct DepthCalibrationConfig {
  // false when the config has no camera.depth_calibration: frames are then
  // published with calibrated = false.
  bool enabled = false;
  int degree = 0;
  // degree + 1 coefficients, ascending powers of d.
  std::vector<double> coefficients_m;
};

// A USB Video Class depth camera (camera.uvc, required when source is uvc).
struct UvcCameraConfig {
  int vendor_id = 0;   // USB idVendor (written as 4 hex digits in the YAML)
  int product_id = 0;  // USB idProduct
  // The camera's USB serial number; "" accepts any camera with these ids.
  std::string serial;
  // Stream format, one little-endian 16-bit count per pixel: "z16", "y16"
  // or "gray16" (y16 and gray16 are the same UVC format GUID).
  std::string format;
  // Millimetres per count (e.g. 1.0, 0.25, 0.125).
  double depth_unit_mm = 0;
  // true when the camera reports radial distance along each pixel's ray
  // (converted to Z with the intrinsics), false when it reports Z.
  bool radial_distance = false;
};

// One fault the simulated camera injects (camera.sim.faults), at
// start_s..start_s+duration_s seconds after the camera started.
struct SimCameraFaultConfig {
  // "frozen_image" (the last image repeats), "stall" (no frames),
  // "pose_drift" (the true camera pose moves away from the calibrated one),
  // "intruding_object" (a box appears in the scene), "pan_tilt_offset"
  // (the pan-tilt head's reading, published on CAMERA_POSE, is off from
  // its true pan and tilt; needs camera.sim.pan_tilt).
  std::string kind;
  double start_s = 0;
  double duration_s = 0;
  // pose_drift: velocity of the optical frame's origin in the pose's frame,
  // m/s, and rotation rate about the optical frame's axes, rad/s.
  Eigen::Vector3d drift_translation_m_per_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d drift_rotation_rad_per_s = Eigen::Vector3d::Zero();
  // intruding_object: an axis-aligned box in the world frame (the robot's
  // root link), its size, its centre at the fault's start and its velocity.
  Eigen::Vector3d object_size_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d object_position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d object_velocity_m_per_s = Eigen::Vector3d::Zero();
  // pan_tilt_offset: reported minus true pan and tilt, radians.
  double pan_offset_rad = 0;
  double tilt_offset_rad = 0;
};

// The simulated ToF camera's error model (camera.sim, required when source
// is sim). Distances r are radial (along the pixel's ray), metres.
struct SimCameraConfig {
  uint64_t seed = 0;
  // Systematic error e(r) = sum_i systematic_error_m[i] * r^i, metres; the
  // camera measures r + e(r).
  std::vector<double> systematic_error_m;
  // Gaussian noise: sigma(r) = noise_sigma0_mm + noise_sigma_per_m2_mm * r^2.
  double noise_sigma0_mm = 0;
  double noise_sigma_per_m2_mm = 0;
  // Amplitude of a surface seen perpendicularly at 1 m (camera units); it
  // falls with 1/r^2 and the cosine of the incidence angle.
  double amplitude_at_1m = 0;
  // Pixels whose amplitude is below this are invalid (depth 0).
  double min_valid_amplitude = 0;
  // Chance per pixel and frame of an invalid pixel from dark noise.
  double dark_pixel_probability = 0;
  // A depth step larger than this between 4-neighbours is a silhouette;
  // silhouette pixels mix both surfaces with this probability.
  double mixed_pixel_jump_m = 0;
  double mixed_pixel_probability = 0;
  std::vector<SimCameraFaultConfig> faults;
  // Pan-tilt head (camera.sim.pan_tilt; absent: a fixed camera). The camera
  // turns about the configured pose: pan about the pose frame's z axis
  // (through the optical centre, right hand rule: positive turns left seen
  // from above when z is up), then tilt about the optical x axis (positive
  // looks up):
  //   R(t) = Rz(pan(t)) * R_configured * Rx(tilt(t)),  translation fixed,
  //   pan(t) = pan_amplitude * sin(2 pi t / pan_period_s),
  //   tilt(t) = tilt_amplitude * sin(2 pi t / tilt_period_s),
  // t seconds since the camera started. The head's reading (what
  // CAMERA_POSE reports per frame) equals the true pan and tilt unless a
  // pan_tilt_offset fault adds to it.
  bool pan_tilt_enabled = false;
  double pan_amplitude_rad = 0;
  double pan_period_s = 1;
  double tilt_amplitude_rad = 0;
  double tilt_period_s = 1;
};

struct CameraConfig {
  std::string id;
  // "sim" (the simulated ToF camera) or "uvc" (a USB Video Class camera).
  std::string source;
  double rate_hz = 0;
  Intrinsics intrinsics;
  // Static calibrated pose, used until a CAMERA_POSE message arrives.
  CameraPose pose;
  DepthCalibrationConfig depth_calibration;
  // The section named by `source` is required; the other one is validated
  // and filled when present.
  UvcCameraConfig uvc;
  SimCameraConfig sim;
};

struct RendererConfig {
  // Which URDF geometry to render: "visual" or "collision".
  std::string geometry;
  // Every shape is inflated by this much, metres.
  double padding_m = 0;
  // Clip distances along the optical axis, metres.
  double near_m = 0;
  double far_m = 0;
  // A camera frame whose utime lies further than this beyond the newest
  // joint state is marked unusable instead of extrapolated, milliseconds.
  double max_extrapolation_ms = 0;
  // Camera poses (CAMERA_POSE) are kept per camera_id for
  // camera_pose_history_ms and looked up at each frame's utime
  // (CameraPoseHistory, docs/renderer.md). Two differing poses at most
  // camera_pose_max_gap_ms apart are a motion (interpolated); a frame
  // further than camera_pose_max_extrapolation_ms beyond a moving camera's
  // newest pose is unusable. Poses further apart are steps (a calibration
  // published now and then): each holds until the next.
  double camera_pose_history_ms = 0;
  double camera_pose_max_extrapolation_ms = 0;
  double camera_pose_max_gap_ms = 0;
  // Prediction from PLANNED_TRAJECTORY (docs/renderer.md): the next frame
  // is rendered ahead at the plan's joints for its expected utime; when the
  // frame comes and every joint interpolated at its utime is within
  // prediction_joint_tolerance_deg (metres for prismatic joints:
  // prediction_joint_tolerance_m) of the prediction, and its camera pose
  // within the pose tolerances, the image rendered ahead is published.
  bool prediction_enabled = false;
  double prediction_joint_tolerance_deg = 0;
  double prediction_joint_tolerance_m = 0;
  double prediction_pose_tolerance_mm = 0;
  double prediction_pose_tolerance_deg = 0;
};

// ---- Safety chain: discrepancy and risk (docs/safety-chain.md) ----

// tofguard-discrepancy: how camera and rendered frames are paired and
// compared.
struct DiscrepancyConfig {
  // Camera noise model: sigma(d) = noise_sigma_at_0m_mm +
  // noise_sigma_per_m2_mm * d^2, d the camera's depth in metres, sigma in mm.
  double noise_sigma_at_0m_mm = 0;
  double noise_sigma_per_m2_mm = 0;
  // A pixel matches when |I_dis| <= tolerance_sigmas * sigma(d) +
  // model_tolerance_mm (the model's own inaccuracy), millimetres.
  double tolerance_sigmas = 0;
  double model_tolerance_mm = 0;
  // A camera frame waits this long (monotonic) for its rendered frame and
  // labels before it is published as unusable, milliseconds.
  double pair_timeout_ms = 0;
  // At most this many frames of each kind wait for their partners.
  int max_pending_frames = 0;
  // Radius of the morphological opening applied to the mismatch mask
  // before blobs and near-arm surfaces are measured, pixels (0 = none).
  int opening_radius_px = 0;
  // Rendered depth steps larger than this (and the model's outline) are
  // silhouettes, where a ToF camera mixes foreground and background (mixed
  // pixels): the pixels on either side of one are left out of the per-link
  // counts and the blobs, millimetres.
  double silhouette_jump_mm = 0;
  // Surfaces nearer than the model within this distance of the modelled
  // arm count as near the arm, metres.
  double near_arm_m = 0;
  // The seed score's logical maximum per pixel, millimetres.
  double max_depth_mm = 0;
  // Optional colour discrepancy image for viewers.
  bool colour_image_enabled = false;
  std::string colour_image_channel;
  double colour_image_full_scale_mm = 0;
};

// tofguard-risk: deadlines, thresholds and debouncing.
struct RiskConfig {
  // How often deadlines are checked (and timeouts re-published), ms.
  double check_period_ms = 0;
  // Staleness deadlines on the receiver's monotonic clock (time since the
  // last valid arrival), milliseconds.
  double depth_deadline_ms = 0;
  double discrepancy_deadline_ms = 0;
  double joint_state_deadline_ms = 0;
  bool camera_pose_required = false;
  double camera_pose_deadline_ms = 0;
  double heartbeat_deadline_ms = 0;
  // Processes (heartbeat_t.process) whose heartbeat must keep coming.
  std::vector<std::string> required_heartbeats;
  // A model mismatch (joint, calibration, object, unclassified) is WARNING
  // until it has held for this many consecutive frames, then DANGEROUS.
  int debounce_frames = 0;
  // The same for per-frame sensor faults (unusable frame, invalid pixels,
  // uncalibrated, frozen).
  int sensor_debounce_frames = 0;
  // Sensor faults.
  double max_invalid_fraction = 0;
  bool calibrated_required = true;
  int frozen_repeat_frames = 0;
  double moving_joint_speed_rad_s = 0;
  // Classification (docs/safety-chain.md).
  int min_link_pixels = 0;
  double link_mismatch_fraction = 0;
  double joint_link_missing_fraction = 0;
  // A link on the way down to the missing links counts as moved (and the
  // joint above it is blamed) when this fraction of it, and at least this
  // many pixels, mismatch.
  double joint_link_affected_fraction = 0;
  int joint_link_affected_min_pixels = 0;
  int min_environment_pixels = 0;
  double calibration_environment_mismatch_fraction = 0;
  double calibration_robot_link_fraction = 0;
  double unknown_object_min_area_m2 = 0;
  double unclassified_blob_area_m2 = 0;

  // The motion estimate (MOTION_ESTIMATE, docs/safety-chain.md): a frame
  // with a model mismatch waits at most estimate_wait_ms (monotonic, from
  // its arrival) for the estimate of its seq, which then names the cause.
  bool estimate_enabled = false;
  double estimate_wait_ms = 0;
  // The estimator takes longer than a frame period on a small CPU, so the
  // newest estimate of an earlier frame of the same camera, at most
  // estimate_max_age_ms older (camera utimes, not wall clock), also serves
  // a frame whose own estimate has not come: the frame does not wait then.
  // Fail safe either way: an estimate only renames a mismatch's cause.
  double estimate_max_age_ms = 0;
  // A joint offset or camera correction is significant when it exceeds
  // estimate_sigmas times its 1-sigma uncertainty and the minimum.
  double estimate_sigmas = 0;
  double estimate_min_joint_offset_deg = 0;
  double estimate_min_joint_offset_m = 0;  // prismatic joints
  double estimate_min_translation_m = 0;
  double estimate_min_rotation_deg = 0;
  // Neither significant, yet the residual after the estimate is above this:
  // something the model lacks (an unknown object), millimetres.
  double estimate_unexplained_residual_mm = 0;

  // The plan (PLANNED_TRAJECTORY): a joint state inside the plan's time
  // span further than this from the plan at its utime is "the arm left its
  // plan" (degrees; metres for prismatic joints).
  bool plan_enabled = false;
  double plan_max_deviation_deg = 0;
  double plan_max_deviation_m = 0;
};

// tofguard-estimator (docs/estimator.md): when to estimate the joint
// offsets and the camera correction that best explain a camera frame.
struct EstimatorConfig {
  // Which parameters are estimated.
  bool estimate_joints = true;
  bool estimate_camera = true;
  // A frame is estimated at once (TRIGGER_WARNING) when its discrepancy_t is
  // usable and its mismatch_fraction reaches warning_mismatch_fraction or
  // its p95_abs_dis_mm reaches warning_p95_abs_dis_mm.
  double warning_mismatch_fraction = 0;
  double warning_p95_abs_dis_mm = 0;
  // At most one warning-triggered frame per warning_min_interval_ms of
  // camera time (frame utimes): on a small CPU the estimator shares the
  // cores with the renderer, whose deadline stops the arm.
  double warning_min_interval_ms = 0;
  // And the newest frame every periodic_period_ms (TRIGGER_PERIODIC),
  // milliseconds.
  double periodic_period_ms = 0;
  // Camera frames kept (by seq) until their discrepancy arrives.
  int max_pending_frames = 0;
  // Frames estimated jointly (MotionEstimator::estimate(frames)): the
  // triggering frame and up to frames_per_estimate - 1 kept frames just
  // before it (at most max_pending_frames in all).
  int frames_per_estimate = 0;
  // Gauss-Newton iterations (one render each) of the joints-and-camera
  // stage, and every pixel_stride-th pixel's depth residual.
  int max_iterations = 0;
  int pixel_stride = 0;
};

// One joint's periodic motion in the simulated arm:
// position = center + amplitude * sin(2*pi*t/period_s + phase), radians (or
// metres for a prismatic joint); t is the arm's motion time, which stands
// still while the arm is halted.
struct JointMotion {
  std::string joint;
  double center = 0;
  double amplitude = 0;
  double period_s = 1;
  double phase_rad = 0;
};

// An encoder fault of the simulated arm: from `at_s` seconds after start,
// joint `joint` reports `offset` (rad or m) more than its true position.
struct EncoderFault {
  std::string joint;
  double offset = 0;
  double at_s = 0;
};

struct JointsSimConfig {
  double rate_hz = 0;
  // The arm halts when the newest SAFETY_STATUS withdraws permission or
  // arrived longer ago than this (monotonic clock), milliseconds.
  double status_deadline_ms = 0;
  // Every movable joint of the URDF, in the order published.
  std::vector<JointMotion> motion;
  std::vector<EncoderFault> faults;
  // The arm's own plan on PLANNED_TRAJECTORY (what an arm controller
  // publishes): plan_rate_hz plans a second, each from now to
  // plan_horizon_ms ahead in steps of plan_step_ms, in the reported
  // (encoder) positions; a halted arm plans to stay where it is.
  bool publish_plan = false;
  double plan_rate_hz = 0;
  double plan_horizon_ms = 0;
  double plan_step_ms = 0;
};

struct InterventionConfig {
  // SAFETY_STATUS rate; a change is published at once as well.
  double publish_rate_hz = 0;
  // No SAFETY_RISK for this long (monotonic) -> power cut, milliseconds.
  double risk_deadline_ms = 0;
  // After a software stop the arm must be still (every |velocity| below
  // stopped_velocity) within stop_deadline_ms, else power cut. A joint state
  // older than joint_state_deadline_ms cannot show that.
  double stop_deadline_ms = 0;
  double joint_state_deadline_ms = 0;
  double stopped_velocity = 0;  // rad/s (or m/s)
  // "lcm" (power_relay_t on channels.power) or "usb_hid_relay".
  std::string power_cut;
  // USB HID relay board (16c0:05df): which relay (1-based) switches the
  // arm's power, wired normally open; serial "" takes the only board.
  int relay_channel = 1;
  std::string relay_serial;
};

// One process of the group tofguard-launch starts, in start order.
struct LaunchedProcess {
  std::string name;
  // argv; "{config}" in any argument becomes the config file's absolute
  // path. A bare program name is looked up beside tofguard-launch, then in
  // PATH.
  std::vector<std::string> command;
  // A required process that keeps crashing is reported loudly; the chain
  // is unsafe without it (the risk classifier sees its heartbeat missing).
  bool required = true;
};

// The black-box recorder: lcm-logger on both LCM URLs into rotating files.
struct RecorderConfig {
  bool enabled = false;
  // A new file every max_file_mb; the oldest files are deleted when all
  // together exceed max_total_mb or are older than max_age_h.
  double max_file_mb = 0;
  double max_total_mb = 0;
  double max_age_h = 0;
};

struct LaunchConfig {
  bool present = false;
  std::vector<LaunchedProcess> processes;
  // Restart back-off: doubles from initial to max.
  double restart_backoff_initial_ms = 0;
  double restart_backoff_max_ms = 0;
  // More restarts than this within restart_window_s -> left stopped.
  int max_restarts = 0;
  double restart_window_s = 0;
  // Each process's stdout/stderr (<name>.log) and the recordings go here;
  // relative to the config file's folder; created when missing.
  std::string log_dir;
  RecorderConfig recorder;
};

struct Config {
  std::string file;
  LcmConfig lcm;
  ChannelNames channels;
  RobotConfig robot;
  EnvironmentConfig environment;
  CameraConfig camera;
  RendererConfig renderer;
  DiscrepancyConfig discrepancy;
  RiskConfig risk;
  EstimatorConfig estimator;
  JointsSimConfig joints_sim;
  InterventionConfig intervention;
  // Optional: only tofguard-launch needs it.
  LaunchConfig launch;
};

// Loads and validates `path`; throws ConfigError. `lcm_default_url_env` is
// the value of LCM_DEFAULT_URL (nullptr when unset).
Config load_config(const std::string& path, const char* lcm_default_url_env);

// Only the LCM URLs (from LCM_DEFAULT_URL or the host-local default) and the
// default channel names: for tools that need no deployment config.
Config default_wire_config(const char* lcm_default_url_env);

// The safety URL: the config's lcm.url, else LCM_DEFAULT_URL, else
// kHostLocalLcmUrl.
constexpr const char* kHostLocalLcmUrl = "udpm://239.255.76.67:7667?ttl=0";
std::string resolve_lcm_url(const std::string& from_config, const char* lcm_default_url_env);

// The image URL when the config names none: for udpm, the same group on the
// next port with recv_buf_size=4194304 (a 176x144..640x480 frame must fit in
// the socket's buffer, or it is silently lost); other providers unchanged.
std::string derive_image_url(const std::string& safety_url);

}  // namespace tofguard
