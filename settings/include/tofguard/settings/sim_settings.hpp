#pragma once
// The simulator's settings: the simulated arm (config section `joints_sim`)
// and the simulated ToF camera (config section `camera.sim`). Durations on
// the clock are integer microseconds, converted once when the file is read;
// the arm's motion parameters stay in seconds (they describe a sine, not a
// deadline).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tofguard/auth/auth_settings.hpp"
#include "tofguard/common/camera_settings.hpp"
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/robot_settings.hpp"
#include "tofguard/common/yaml_reader.hpp"
#include "tofguard/settings/depth_camera_settings.hpp"

namespace tofguard::settings {

// ---- The simulated arm (joints_sim) ----

// One joint's periodic motion (joints_sim.motion.<joint>):
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

// An encoder fault of the simulated arm (joints_sim.faults): from `at_s`
// seconds of motion time after start, joint `joint` reports `offset` (rad or
// m) more than its true position.
struct EncoderFault {
  std::string joint;
  double offset = 0;
  double at_s = 0;
};

// One pose of the simulated arm's task (joints_sim.task.waypoints): every
// movable joint's position (rad, m for prismatic joints), held for hold_s.
struct TaskWaypoint {
  std::string name;
  double hold_s = 0;
  std::map<std::string, double> joints;
};

struct JointsSimSettings {
  // rate_hz: JOINT_STATE rate.
  double rate_hz = 0;
  // status_deadline_ms: the arm halts when the newest SAFETY_STATUS
  // withdraws permission or arrived longer ago than this (monotonic clock);
  // microseconds.
  int64_t status_deadline_us = 0;
  // motion: every movable joint of the URDF, in the order published.
  std::vector<JointMotion> motion;
  // task (optional; tofguard-joints-sim --task follows it instead of
  // motion): a cycle of waypoints, each held for its hold_s, then moved to
  // the next (the last to the first) in move_s seconds along a straight
  // line in joint space with a cosine speed profile (at rest at both ends).
  std::vector<TaskWaypoint> task_waypoints;
  double task_move_s = 0;
  // faults (optional).
  std::vector<EncoderFault> faults;
  // plan.{publish, rate_hz, horizon_ms, step_ms}: the arm's own plan on
  // PLANNED_TRAJECTORY (what an arm controller publishes): plan_rate_hz
  // plans a second, each from now to plan_horizon ahead in steps of
  // plan_step, in the reported (encoder) positions; a halted arm plans to
  // stay where it is. Microseconds.
  bool publish_plan = false;
  double plan_rate_hz = 0;
  int64_t plan_horizon_us = 0;
  int64_t plan_step_us = 0;
  // follow_speed_limit (optional; absent: the arm keeps its speed, as a
  // controller that ignores SAFETY_SPEED_LIMIT): the arm slows its motion
  // (a time scale in [0, 1] on the periodic motion) to keep its speed
  // bound at most margin times the newest verified limit, and to 0 when
  // the limit has expired (its valid_for_ms). It learns its full-speed bound
  // from each limit (the limit's arm_speed_m_s over the scale of the joint
  // state it was computed from); speeding back up is limited to
  // ramp_per_s of full speed per second (when the limit rises, or while
  // it has no bound to go by).
  bool follow_speed_limit = false;
  double speed_limit_margin = 1;
  double speed_ramp_per_s = 0;
};

// Reads (and finishes) the `joints_sim` section.
JointsSimSettings read_joints_sim_settings(YamlMap section);

// Everything tofguard-joints-sim needs.
struct JointsSimProcessSettings {
  LcmSettings lcm;
  ChannelNames channels;
  RobotSettings robot;
  // The config file's path, for the errors SimulatedArm finds against the
  // URDF.
  std::string config_file;
  // As the arm's controller: with a key it takes the permission to move only
  // from the verified SAFETY_STATUS_AUTH.
  auth::AuthSettings auth;
  JointsSimSettings joints_sim;
  // tofguard-joints-sim --commissioning: the arm moves without a permission
  // to move, as a real arm moves under its own controller (and a person's
  // eyes) while a camera is commissioned and tofguard does not yet judge
  // its frames (docs/camera.md, "Commissioning a camera"). Never in a
  // deployment: the simulator's alone.
  bool moves_without_permission = false;
  // tofguard-joints-sim --task: the arm follows joints_sim.task instead of
  // the periodic motion (the assistive task scripts/demo shows).
  bool follows_task = false;
};

// ---- The simulated ToF camera (camera.sim) ----

// One fault the simulated camera injects (camera.sim.faults), at
// start..start+duration after the camera started.
struct SimCameraFaultSettings {
  // kind: "frozen_image" (the last image repeats), "stall" (no frames),
  // "pose_drift" (the true camera pose moves away from the calibrated one),
  // "intruding_object" (a box appears in the scene), "pan_tilt_offset"
  // (the pan-tilt head's reading, published on CAMERA_POSE, is off from
  // its true pan and tilt; needs camera.sim.pan_tilt).
  std::string kind;
  // start_s, duration_s: microseconds.
  int64_t start_us = 0;
  int64_t duration_us = 0;
  // pose_drift: velocity of the optical frame's origin in the pose's frame,
  // m/s, and rotation rate about the optical frame's axes, rad/s.
  Eigen::Vector3d drift_translation_m_per_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d drift_rotation_rad_per_s = Eigen::Vector3d::Zero();
  // intruding_object: an axis-aligned box in the world frame (the robot's
  // root link), its size, its centre at the fault's start and its velocity.
  Eigen::Vector3d object_size_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d object_position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d object_velocity_m_per_s = Eigen::Vector3d::Zero();
  // pan_tilt_offset (pan_offset_deg, tilt_offset_deg): reported minus true
  // pan and tilt, radians.
  double pan_offset_rad = 0;
  double tilt_offset_rad = 0;
};

// The simulated camera's residual errors (camera.sim.residual): what a
// real ToF camera still gets wrong after its distance calibration. These
// are the simulator's truth only; nothing downstream of the camera knows
// them. All zeros (the mapping absent) is an ideal camera. Distances r are
// radial (along the pixel's ray), metres; every term adds to the measured r.
struct SimResidualSettings {
  // wiggle_{amplitude_mm, period_m, phase_rad}, slope_mm_per_m: an error
  // smooth in r (what a calibration polynomial leaves of the camera's
  // periodic "wiggling"), millimetres:
  //   wiggle_amplitude_mm * sin(2 pi r / wiggle_period_m + wiggle_phase_rad)
  //   + slope_mm_per_m * r.
  double wiggle_amplitude_mm = 0;
  double wiggle_period_m = 1;
  double wiggle_phase_rad = 0;
  double slope_mm_per_m = 0;
  // pixel_offset_sigma_mm: fixed-pattern noise, a per-pixel offset drawn
  // once per camera (from camera.sim.seed, N(0, sigma)) and the same in
  // every frame, millimetres.
  double pixel_offset_sigma_mm = 0;
  // reflectivity_bias_mm_per_decade, reference_amplitude: a bias with the
  // pixel's amplitude A (dark or far surfaces return less light),
  //   reflectivity_bias_mm_per_decade * log10(A / reference_amplitude) mm;
  // reference_amplitude (camera units, as amplitude.at_1m) is the amplitude
  // that reads without bias (the calibration target's).
  double reflectivity_bias_mm_per_decade = 0;
  double reference_amplitude = 1;
  // multipath_max_mm: the most a pixel reads farther from light that
  // reaches its surface over another one (a concave corner), millimetres
  // (TofErrorModel explains the approximation).
  double multipath_max_mm = 0;
  // warmup_{drift_mm, time_constant_s}: common-mode drift while the camera
  // warms up, t seconds since it was switched on:
  //   warmup_drift_mm * (1 - exp(-t / warmup_time_constant_s)) mm.
  // on_before_start_s (optional; absent: 0, switched on with the process):
  // how long the camera had been on when tofguard-camera started, t then
  // counts from there; a camera warmed up before it is commissioned and
  // used (docs/camera.md) has drifted most of the way.
  double warmup_drift_mm = 0;
  double warmup_time_constant_s = 1;
  double on_before_start_s = 0;
};

// The simulated ToF camera's error model (camera.sim, required when
// camera.source is sim). Distances r are radial (along the pixel's ray),
// metres.
// camera.sim.user (optional; absent: the chair is empty): the simulated
// wheelchair user the camera sees, the truth the monitor knows only through
// its occupant model and envelopes (config occupant:). Moves about the
// model's pose, t seconds since the camera started:
//   breathing: the chest and the abdomen forward by breathing_mm/2 *
//     (1 - cos(2 pi t / breathing_period_s)) (0..breathing_mm);
//   head: the skull, face and neck turned about the neck's vertical axis by
//     head_turn_deg * sin(2 pi t / head_period_s);
//   hand: the right hand forward and back along the seat by hand_motion_m *
//     sin(2 pi t / hand_period_s).
// Forward and vertical are the seat frame's x and z (the occupant URDF's).
struct SimUserSettings {
  std::string urdf_path;  // urdf (resolved): an occupant model
  std::string seated_on;  // the environment link it sits on
  double breathing_mm = 0;
  double breathing_period_s = 1;
  double head_turn_rad = 0;  // head_turn_deg in the file
  double head_period_s = 1;
  double hand_motion_m = 0;
  double hand_period_s = 1;
};

struct SimCameraSettings {
  uint64_t seed = 0;
  // exposure_offset_ms (optional, 0..the frame period; absent: 0): the
  // camera exposes this long after each whole frame period of the
  // computer's monotonic clock, so that cameras simulated on one computer
  // expose in turn, as time-multiplexed ToF cameras are triggered so that
  // none sees another's light (docs/camera.md, "The second camera"). Every
  // camera with the same offset exposes at the same instant.
  double exposure_offset_ms = 0;
  // systematic_error_m: systematic error e(r) = sum_i systematic_error_m[i]
  // * r^i, metres; the camera measures r + e(r).
  std::vector<double> systematic_error_m;
  // noise.{sigma0_mm, sigma_per_m2_mm}: Gaussian noise:
  // sigma(r) = noise_sigma0_mm + noise_sigma_per_m2_mm * r^2.
  double noise_sigma0_mm = 0;
  double noise_sigma_per_m2_mm = 0;
  // amplitude.at_1m: amplitude of a surface seen perpendicularly at 1 m
  // (camera units); it falls with 1/r^2 and the cosine of the incidence
  // angle.
  double amplitude_at_1m = 0;
  // amplitude.min_valid: pixels whose amplitude is below this are invalid
  // (depth 0).
  double min_valid_amplitude = 0;
  // amplitude.dark_pixel_probability: chance per pixel and frame of an
  // invalid pixel from dark noise.
  double dark_pixel_probability = 0;
  // mixed_pixels.{jump_m, probability}: a depth step larger than this
  // between 4-neighbours is a silhouette; silhouette pixels mix both
  // surfaces with this probability.
  double mixed_pixel_jump_m = 0;
  double mixed_pixel_probability = 0;
  // residual (optional): errors left after the distance calibration;
  // absent: none (an ideal camera).
  SimResidualSettings residual;
  std::vector<SimCameraFaultSettings> faults;
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
  std::optional<SimUserSettings> user;
};

// Reads (and finishes) the `camera.sim` section.
SimCameraSettings read_sim_camera_settings(YamlMap section);

// Everything tofguard-camera needs with camera.source sim.
struct SimCameraProcessSettings {
  LcmSettings lcm;
  ChannelNames channels;
  RobotSettings robot;
  EnvironmentSettings environment;
  CameraSettings camera;
  // renderer.{near_m, far_m}: the simulated camera renders the scene with
  // the renderer's clip distances, metres.
  double near_m = 0;
  double far_m = 0;
  camera::DepthCalibrationSettings depth_calibration;
  SimCameraSettings sim;
};

// Everything tofguard-sim-fault needs (it runs with or without a config).
struct SimFaultToolSettings {
  LcmSettings lcm;
  ChannelNames channels;
  // camera.id: the camera a camera fault is for ("" without a config).
  std::string camera_id;
};

}  // namespace tofguard::settings

// The component's own names for its settings (tofguard::sim::JointMotion, ...).
namespace tofguard::sim {
using settings::EncoderFault;
using settings::JointMotion;
using settings::JointsSimProcessSettings;
using settings::JointsSimSettings;
using settings::read_joints_sim_settings;
using settings::read_sim_camera_settings;
using settings::SimCameraFaultSettings;
using settings::SimCameraProcessSettings;
using settings::SimCameraSettings;
using settings::SimFaultToolSettings;
using settings::SimResidualSettings;
using settings::SimUserSettings;
using settings::TaskWaypoint;
}  // namespace tofguard::sim
