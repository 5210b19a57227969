#include "tofguard/deployment/config.hpp"

#include "tofguard/common/yaml_reader.hpp"

namespace tofguard::deployment {

Config default_wire_config(const char* lcm_default_url_env) {
  Config config;
  config.file = "(no config: defaults)";
  config.lcm = read_lcm_settings(std::nullopt, lcm_default_url_env);
  return config;
}

std::vector<std::string> start_warnings(const Config& config) {
  std::vector<std::string> warnings;
  if (const std::string w = auth::auth_warning(config.auth); !w.empty()) warnings.push_back(w);
  if (const std::string w = bus_exposure_warning(config.lcm.url); !w.empty()) warnings.push_back(w);
  if (config.lcm.image_url != config.lcm.url) {
    if (const std::string w = bus_exposure_warning(config.lcm.image_url); !w.empty()) warnings.push_back(w);
  }
  return warnings;
}

Config load_config(const std::string& path, const char* lcm_default_url_env) {
  YamlMap root = load_yaml_file(path);
  Config config;
  config.file = path;
  config.lcm = read_lcm_settings(root.optional_map("lcm"), lcm_default_url_env);
  if (auto channels = root.optional_map("channels")) config.channels = read_channel_names(*channels);
  config.auth = auth::read_auth_settings(root);
  config.robot = read_robot_settings(root.map("robot"));
  config.environment = read_environment_settings(root.optional_map("environment"));
  config.occupant = settings::read_occupant_settings(root.optional_map("occupant"));

  {
    YamlMap camera = root.map("camera");
    CameraSection& c = config.camera;
    c.id = camera.string("id");
    c.source = camera.choice("source", {"sim", "uvc"});
    c.rate_hz = camera.number("rate_hz", 0.1, 1000);
    YamlMap intrinsics = camera.map("intrinsics");
    c.intrinsics = read_intrinsics(intrinsics);
    intrinsics.finish();
    c.pose = read_camera_pose(camera.map("pose"));
    if (camera.optional("depth_calibration")) {
      c.depth_calibration = camera::read_depth_calibration_settings(camera.map("depth_calibration"));
    }
    if (c.source == "uvc" || camera.optional("uvc")) c.uvc = camera::read_uvc_settings(camera.map("uvc"));
    if (c.source == "sim" || camera.optional("sim")) c.sim = sim::read_sim_camera_settings(camera.map("sim"));
    camera.finish();
  }

  config.renderer = renderer::read_renderer_settings(root.map("renderer"));
  // Safety chain sections (required: no silent defaults for thresholds).
  {
    YamlMap discrepancy = root.map("discrepancy");
    config.discrepancy = discrepancy::read_discrepancy_settings(discrepancy);
    // The profile must be this camera's: checked here, once, as a frame of
    // it would be (profile_mismatch).
    if (config.discrepancy.camera_profile) {
      depth_image_t frame;
      frame.camera_id = config.camera.id;
      frame.width = config.camera.intrinsics.width;
      frame.height = config.camera.intrinsics.height;
      frame.fx = config.camera.intrinsics.fx;
      frame.fy = config.camera.intrinsics.fy;
      frame.cx = config.camera.intrinsics.cx;
      frame.cy = config.camera.intrinsics.cy;
      if (const std::string why = profile_mismatch(*config.discrepancy.camera_profile, frame); !why.empty())
        discrepancy.fail("camera_profile", "a profile of the camera section's camera", why);
    }
  }
  config.risk = risk::read_risk_settings(root.map("risk"));
  config.estimator = estimator::read_estimator_settings(root.map("estimator"));
  config.joints_sim = sim::read_joints_sim_settings(root.map("joints_sim"));
  config.intervene = intervene::read_intervene_settings(root.map("intervention"));
  if (auto launch = root.optional_map("launch")) config.launch = launch::read_launch_settings(*launch);

  root.finish();
  return config;
}

}  // namespace tofguard::deployment
