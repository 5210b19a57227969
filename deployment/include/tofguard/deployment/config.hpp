#pragma once
// The deployment config: one YAML file per deployment (config/sim.yaml is the
// embedded default). Every process loads and validates the whole file at
// start, so that a config error stops every process the same way, with one
// line naming the file, the key and what was expected (ConfigError, exit
// code 2), before anything is published.
//
// This loader composes the sections; each section's settings struct and
// reader live beside the component that uses it (renderer_settings.hpp,
// risk_settings.hpp, ...), the pieces several processes share in common
// (lcm_settings.hpp, robot_settings.hpp, camera_settings.hpp). Each process
// is handed only what it needs (process_settings.hpp).
//
// Units are in the YAML keys: _m metres, _ms milliseconds, _s seconds, _hz
// hertz, _mm millimetres. Durations are converted once, here, to integer
// microseconds (fields named _us). Relative paths are resolved against the
// config file's folder.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/auth/auth_settings.hpp"
#include "tofguard/common/camera_profile.hpp"
#include "tofguard/common/camera_settings.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/robot_settings.hpp"
#include "tofguard/settings/depth_camera_settings.hpp"
#include "tofguard/settings/discrepancy_settings.hpp"
#include "tofguard/settings/estimator_settings.hpp"
#include "tofguard/settings/intervene_settings.hpp"
#include "tofguard/settings/launch_settings.hpp"
#include "tofguard/settings/occupant_settings.hpp"
#include "tofguard/settings/renderer_settings.hpp"
#include "tofguard/settings/risk_settings.hpp"
#include "tofguard/settings/sim_settings.hpp"

namespace tofguard::deployment {

// One camera: the `camera` section, or one entry of the `cameras` list. What
// every process of that camera shares (id, rate_hz, intrinsics, pose) and
// the sources' own settings.
struct CameraSection : CameraSettings {
  // source: "sim" (the simulated ToF camera) or "uvc" (a USB Video Class
  // camera).
  std::string source;
  // depth_calibration (optional; disabled when absent).
  camera::DepthCalibrationSettings depth_calibration;
  // The section named by `source` is required; the other one is validated
  // and filled when present.
  camera::UvcSettings uvc;
  sim::SimCameraSettings sim;
  // The camera's commissioned profile (docs/camera.md, "Commissioning a
  // camera"): cameras[i].camera_profile, or for a lone `camera` section
  // discrepancy.camera_profile; null without one.
  std::shared_ptr<const CameraProfile> profile;
  // What this camera's channels and processes are called: "" for the first
  // camera (its channels keep the names of `channels`, its processes theirs),
  // "/<id>" appended for every other (camera_channel_names, lcm_settings.hpp).
  std::string name_suffix;
};

struct Config {
  std::string file;
  LcmSettings lcm;
  ChannelNames channels;
  // Required: a key, or an explicit insecure: true.
  auth::AuthSettings auth;
  RobotSettings robot;
  EnvironmentSettings environment;
  // Optional: the wheelchair's occupant (absent: nobody is modelled).
  std::optional<OccupantSettings> occupant;
  // Every camera, in config order: the `cameras` list, or the lone `camera`
  // section as a list of one.
  std::vector<CameraSection> cameras;
  // The camera this process serves (select_camera below), and `channels`
  // are its channel names; until a camera is selected, the first.
  CameraSection camera;
  renderer::RendererSettings renderer;
  discrepancy::DiscrepancySettings discrepancy;
  risk::RiskSettings risk;
  estimator::EstimatorSettings estimator;
  sim::JointsSimSettings joints_sim;
  intervene::InterveneSettings intervene;
  // Optional: only tofguard-launch needs it.
  std::optional<launch::LaunchSettings> launch;
};

// Loads and validates `path`; throws ConfigError. `lcm_default_url_env` is
// the value of LCM_DEFAULT_URL (nullptr when unset).
Config load_config(const std::string& path, const char* lcm_default_url_env);

// The config as the processes of camera `id` see it: `camera` that camera,
// `channels` its channel names, discrepancy.camera_profile its profile.
// Throws ConfigError naming the configured ids when `id` is none of them.
Config select_camera(const Config& config, const std::string& id);

// The loud lines every process prints at start for this config: running
// without authentication, an LCM bus open beyond the host.
std::vector<std::string> start_warnings(const Config& config);

// Only the LCM URLs (from LCM_DEFAULT_URL or the host-local default) and the
// default channel names: for tools that need no deployment config.
Config default_wire_config(const char* lcm_default_url_env);

}  // namespace tofguard::deployment
