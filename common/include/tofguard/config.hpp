#pragma once
// The deployment config: one YAML file per deployment (config/sim.yaml is the
// embedded default). Every process loads and validates the whole file at
// start, so that a config error stops every process the same way, with one
// line naming the file, the key and what was expected (ConfigError, exit
// code 2), before anything is published.
//
// Units are in the names: _m metres, _ms milliseconds, _hz hertz, _mm
// millimetres. Relative paths are resolved against the config file's folder.
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/config_error.hpp"

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
  // Simulation only: the simulated arm's true joint state (for the simulated
  // camera) and run-time encoder fault injection.
  std::string sim_true_joint_state = "SIM_TRUE_JOINT_STATE";
  std::string sim_joint_fault = "SIM_JOINT_FAULT";
};

// Pinhole intrinsics, OpenCV convention (pixel (u, v) has its centre at
// (u, v), u right, v down), in pixels.
struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0;
  double fy = 0;
  double cx = 0;
  double cy = 0;
};

// Pose of the camera's optical frame (x right, y down, z forward) in URDF
// link `frame_id`: p_frame = rotation * p_optical + translation_m.
struct CameraPose {
  std::string frame_id;
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
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

struct CameraConfig {
  std::string id;
  // "sim" (the simulated ToF camera) or "uvc" (a USB Video Class camera).
  std::string source;
  double rate_hz = 0;
  Intrinsics intrinsics;
  // Static calibrated pose, used until a CAMERA_POSE message arrives.
  CameraPose pose;
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
  int min_environment_pixels = 0;
  double calibration_environment_mismatch_fraction = 0;
  double calibration_robot_link_fraction = 0;
  double unknown_object_min_area_m2 = 0;
  double unclassified_blob_area_m2 = 0;
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
