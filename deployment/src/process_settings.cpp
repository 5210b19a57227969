#include "tofguard/deployment/process_settings.hpp"

#include <algorithm>
#include <cmath>

#include "tofguard/common/process.hpp"

namespace tofguard::deployment {

renderer::RendererProcessSettings renderer_process_settings(const Config& config) {
  renderer::RendererProcessSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.robot = config.robot;
  s.occupant = config.occupant;
  s.environment = config.environment;
  s.camera = config.camera;
  s.renderer = config.renderer;
  return s;
}

discrepancy::DiscrepancyProcessSettings discrepancy_process_settings(const Config& config) {
  discrepancy::DiscrepancyProcessSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.camera_id = config.camera.id;
  s.discrepancy = config.discrepancy;
  const ChannelNames base = base_channel_names(config.channels);
  for (const CameraSection& camera : config.cameras) {
    if (camera.id == config.camera.id) continue;
    const ChannelNames its = camera_channel_names(base, camera.name_suffix);
    s.witnesses.push_back({camera.id, its.depth, its.labels, camera.rate_hz, camera.profile});
  }
  s.detection_capability_m = std::sqrt(config.risk.unknown_object_min_area_m2);
  s.approach_speed_m_s = config.risk.field_approach_speed_m_s;
  return s;
}

risk::RiskProcessSettings risk_process_settings(const Config& config) {
  risk::RiskProcessSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.occupant = config.occupant;
  s.robot_urdf_path = config.robot.urdf_path;
  s.robot_package_paths = config.robot.package_paths;
  s.rendered_geometry = config.renderer.geometry;
  for (const CameraSection& camera : config.cameras) {
    risk::RiskCamera c;
    c.id = camera.id;
    c.rate_hz = camera.rate_hz;
    c.channels = camera_channel_names(config.channels, camera.name_suffix);
    for (const std::string& process : config.risk.required_heartbeats) {
      const std::vector<std::string>& per_camera = per_camera_process_names();
      const bool of_a_camera = std::find(per_camera.begin(), per_camera.end(), process) != per_camera.end();
      c.required_heartbeats.push_back(of_a_camera ? process + camera.name_suffix : process);
    }
    s.cameras.push_back(std::move(c));
  }
  s.auth = config.auth;
  s.risk = config.risk;
  return s;
}

estimator::EstimatorProcessSettings estimator_process_settings(const Config& config) {
  estimator::EstimatorProcessSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.robot = config.robot;
  s.environment = config.environment;
  s.camera = config.camera;
  s.renderer = config.renderer;
  s.noise_sigma_at_0m_mm = config.discrepancy.noise_sigma_at_0m_mm;
  s.noise_sigma_per_m2_mm = config.discrepancy.noise_sigma_per_m2_mm;
  s.camera_profile = config.discrepancy.camera_profile;
  s.estimator = config.estimator;
  s.occupant = config.occupant;
  if (config.cameras.size() > 1) s.hidden_nearer_than_m = config.discrepancy.near_arm_m;
  s.several_cameras = config.cameras.size() > 1;
  return s;
}

intervene::InterveneProcessSettings intervene_process_settings(const Config& config) {
  intervene::InterveneProcessSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.auth = config.auth;
  s.intervene = config.intervene;
  return s;
}

intervene::ResetToolSettings reset_tool_settings(const Config& config) {
  intervene::ResetToolSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.auth = config.auth;
  return s;
}

sim::JointsSimProcessSettings joints_sim_process_settings(const Config& config) {
  sim::JointsSimProcessSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.robot = config.robot;
  s.config_file = config.file;
  s.auth = config.auth;
  s.joints_sim = config.joints_sim;
  return s;
}

sim::SimCameraProcessSettings sim_camera_process_settings(const Config& config) {
  sim::SimCameraProcessSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.robot = config.robot;
  s.environment = config.environment;
  s.camera = config.camera;
  s.near_m = config.renderer.near_m;
  s.far_m = config.renderer.far_m;
  s.depth_calibration = config.camera.depth_calibration;
  s.sim = config.camera.sim;
  return s;
}

sim::SimFaultToolSettings sim_fault_tool_settings(const Config& config) {
  sim::SimFaultToolSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.camera_id = config.camera.id;
  return s;
}

camera::UvcCameraProcessSettings uvc_camera_process_settings(const Config& config) {
  camera::UvcCameraProcessSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.camera = config.camera;
  s.depth_calibration = config.camera.depth_calibration;
  s.uvc = config.camera.uvc;
  return s;
}

launch::LaunchProcessSettings launch_process_settings(const Config& config) {
  if (!config.launch) {
    throw ConfigError(
        config.file +
        ": launch: missing key, expected a mapping with processes, restart settings, log_dir, recorder");
  }
  launch::LaunchProcessSettings s;
  s.config_file = config.file;
  s.lcm = config.lcm;
  s.launch = *config.launch;
  return s;
}

view::ViewSettings view_settings(const Config& config) {
  view::ViewSettings s;
  s.lcm = config.lcm;
  s.channels = config.channels;
  s.discrepancy = config.discrepancy;
  s.far_m = config.renderer.far_m;
  s.camera_rate_hz = config.camera.rate_hz;
  // (fields.protective_at_rest_m is the risk rules' S at rest: tofguard-view
  // computes it with them, apps/tofguard-view.cpp.)
  s.fields.warning_margin_m = config.risk.field_warning_margin_m;
  return s;
}

}  // namespace tofguard::deployment
