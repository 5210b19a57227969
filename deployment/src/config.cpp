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

namespace {

// One camera's section (`camera`, or an entry of `cameras`); `profile_key`:
// whether its profile is its own key (an entry of `cameras`) rather than
// discrepancy.camera_profile (a lone `camera`).
CameraSection read_camera_section(YamlMap& camera, bool profile_key) {
  CameraSection c;
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
  if (c.source == "sim" || camera.optional("sim")) {
    c.sim = sim::read_sim_camera_settings(camera.map("sim"));
    if (c.sim.exposure_offset_ms >= 1000 / c.rate_hz) {
      camera.map("sim").fail(
          "exposure_offset_ms",
          "less than the frame period, " + std::to_string(1000 / c.rate_hz) + " ms at rate_hz",
          std::to_string(c.sim.exposure_offset_ms));
    }
  }
  if (profile_key && camera.optional("camera_profile")) {
    c.profile =
        std::make_shared<const CameraProfile>(read_camera_profile(camera.existing_path("camera_profile")));
  }
  return c;
}

// The profile must be its camera's: checked here, once, as a frame of it
// would be (profile_mismatch). `where` fails at the profile's key.
void check_profile_is_the_cameras(const CameraSection& camera, const YamlMap& where, const std::string& key) {
  if (!camera.profile) return;
  if (const std::string why = profile_mismatch(*camera.profile, camera.id, camera.intrinsics); !why.empty())
    where.fail(key, "a profile of camera '" + camera.id + "'", why);
}

// `camera` (one camera; its profile is discrepancy.camera_profile) or
// `cameras` (a list; each names its own profile), never both. Ids are
// unique; the first camera's names carry no suffix, every other's "/<id>".
std::vector<CameraSection> read_cameras(YamlMap& root, YamlMap& discrepancy,
                                        const std::shared_ptr<const CameraProfile>& lone_camera_profile) {
  std::vector<CameraSection> cameras;
  if (root.has("cameras")) {
    if (root.has("camera")) root.fail("camera", "either a camera section or a cameras list, not both");
    if (lone_camera_profile) {
      discrepancy.fail("camera_profile", "no profile here with a cameras list: each camera names its own",
                       "cameras[i].camera_profile");
    }
    std::vector<YamlMap> entries = root.maps("cameras");
    if (entries.empty()) root.fail("cameras", "a list of at least one camera", "an empty list");
    for (YamlMap& entry : entries) {
      CameraSection c = read_camera_section(entry, true);
      for (const CameraSection& other : cameras) {
        if (other.id == c.id) entry.fail("id", "an id no other camera has", "'" + c.id + "' again");
      }
      check_profile_is_the_cameras(c, entry, "camera_profile");
      c.name_suffix = cameras.empty() ? "" : "/" + c.id;
      entry.finish();
      cameras.push_back(std::move(c));
    }
  } else {
    YamlMap camera = root.map("camera");
    CameraSection c = read_camera_section(camera, false);
    camera.finish();
    c.profile = lone_camera_profile;
    check_profile_is_the_cameras(c, discrepancy, "camera_profile");
    cameras.push_back(std::move(c));
  }
  return cameras;
}

}  // namespace

Config select_camera(const Config& config, const std::string& id) {
  std::string ids;
  for (const CameraSection& camera : config.cameras) {
    if (camera.id == id) {
      Config selected = config;
      selected.camera = camera;
      selected.channels = camera_channel_names(config.channels, camera.name_suffix);
      selected.discrepancy.camera_profile = camera.profile;
      return selected;
    }
    ids += (ids.empty() ? "'" : ", '") + camera.id + "'";
  }
  throw ConfigError(config.file + ": cameras: no camera '" + id + "'; the config has " + ids);
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

  config.renderer = renderer::read_renderer_settings(root.map("renderer"));
  // Safety chain sections (required: no silent defaults for thresholds).
  YamlMap discrepancy = root.map("discrepancy");
  config.discrepancy = discrepancy::read_discrepancy_settings(discrepancy);
  config.cameras = read_cameras(root, discrepancy, config.discrepancy.camera_profile);
  config.camera = config.cameras.front();
  config.discrepancy.camera_profile = config.camera.profile;
  config.risk = risk::read_risk_settings(root.map("risk"));
  config.estimator = estimator::read_estimator_settings(root.map("estimator"));
  config.joints_sim = sim::read_joints_sim_settings(root.map("joints_sim"));
  config.intervene = intervene::read_intervene_settings(root.map("intervention"));
  if (auto launch = root.optional_map("launch")) config.launch = launch::read_launch_settings(*launch);

  root.finish();
  return config;
}

}  // namespace tofguard::deployment
