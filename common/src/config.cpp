#include "tofguard/common/config.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <regex>

#include "tofguard/common/yaml_reader.hpp"

namespace tofguard {
namespace {

// The rule is Intrinsics::check (camera_geometry.hpp); the YAML keys are its
// field names, so a violation names the key.
Intrinsics read_intrinsics(YamlMap& map) {
  constexpr double kAny = std::numeric_limits<double>::max();
  constexpr int64_t kAnyInt = std::numeric_limits<int>::max();
  const int width = static_cast<int>(map.integer("width", -kAnyInt, kAnyInt));
  const int height = static_cast<int>(map.integer("height", -kAnyInt, kAnyInt));
  const double fx = map.number("fx", -kAny, kAny);
  const double fy = map.number("fy", -kAny, kAny);
  const double cx = map.number("cx", -kAny, kAny);
  const double cy = map.number("cy", -kAny, kAny);
  if (auto v = Intrinsics::check(width, height, fx, fy, cx, cy)) map.fail(v->field, v->expected, v->got);
  return Intrinsics(width, height, fx, fy, cx, cy);
}

// The rule is CameraPose::check; `frame` is a non-empty string and the
// numbers are finite by YamlMap's reading, so only the quaternion's norm is
// left to refuse here, under its own key.
CameraPose read_pose(YamlMap map) {
  const std::string frame = map.string("frame");
  const auto t = map.numbers("translation_m", 3);
  const auto q = map.numbers("rotation_wxyz", 4);
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (auto v = UnitQuaternion::check(rotation, kConfigQuaternionTolerance, "rotation_wxyz")) {
    map.fail(v->field, v->expected, v->got);
  }
  map.finish();
  return CameraPose(frame, Eigen::Vector3d(t[0], t[1], t[2]), UnitQuaternion(rotation, kConfigQuaternionTolerance));
}

DepthCalibrationConfig read_depth_calibration(YamlMap map) {
  DepthCalibrationConfig c;
  c.enabled = true;
  c.degree = static_cast<int>(map.integer("degree", 0, 9));
  c.coefficients_m = map.numbers("coefficients_m", c.degree + 1);
  map.finish();
  return c;
}

int read_usb_id(YamlMap& map, const std::string& key) {
  static const std::regex hex4("^[0-9a-fA-F]{4}$");
  const std::string text = map.string(key);
  if (!std::regex_match(text, hex4)) {
    map.fail(key, "a USB id as 4 hex digits in quotes, as lsusb shows it (e.g. \"2bc5\")",
             "\"" + text + "\"");
  }
  return std::stoi(text, nullptr, 16);
}

UvcCameraConfig read_uvc(YamlMap map) {
  UvcCameraConfig c;
  c.vendor_id = read_usb_id(map, "vendor_id");
  c.product_id = read_usb_id(map, "product_id");
  c.serial = map.optional_string("serial").value_or("");
  c.format = map.choice("format", {"z16", "y16", "gray16"});
  c.depth_unit_mm = map.number("depth_unit_mm", 1e-3, 100);
  c.radial_distance = map.choice("distance", {"z", "radial"}) == "radial";
  map.finish();
  return c;
}

Eigen::Vector3d vector3(YamlMap& map, const std::string& key, double limit) {
  const auto v = map.numbers(key, 3);
  for (double x : v) {
    if (std::abs(x) > limit) {
      map.fail(key, "3 numbers each in [-" + std::to_string(limit) + ", " +
                        std::to_string(limit) + "]",
               std::to_string(x));
    }
  }
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

SimCameraFaultConfig read_sim_fault(YamlMap map) {
  SimCameraFaultConfig f;
  f.kind = map.choice("kind", {"frozen_image", "stall", "pose_drift", "intruding_object", "pan_tilt_offset"});
  f.start_s = map.number("start_s", 0, 1e6);
  f.duration_s = map.number("duration_s", 0, 1e6);
  if (f.kind == "pose_drift") {
    f.drift_translation_m_per_s = vector3(map, "translation_m_per_s", 10);
    f.drift_rotation_rad_per_s = vector3(map, "rotation_rad_per_s", 10);
  } else if (f.kind == "intruding_object") {
    f.object_size_m = vector3(map, "size_m", 10);
    if (f.object_size_m.minCoeff() <= 0) map.fail("size_m", "3 sizes > 0");
    f.object_position_m = vector3(map, "position_m", 100);
    if (map.optional("velocity_m_per_s")) {
      f.object_velocity_m_per_s = vector3(map, "velocity_m_per_s", 10);
    }
  } else if (f.kind == "pan_tilt_offset") {
    f.pan_offset_rad = map.number("pan_offset_deg", -180, 180) * M_PI / 180.0;
    f.tilt_offset_rad = map.number("tilt_offset_deg", -90, 90) * M_PI / 180.0;
  }
  map.finish();
  return f;
}

SimCameraConfig read_sim(YamlMap map) {
  SimCameraConfig c;
  c.seed = static_cast<uint64_t>(map.integer("seed", 0, INT64_MAX));
  c.systematic_error_m = map.numbers("systematic_error_m", -1);
  if (c.systematic_error_m.empty() || c.systematic_error_m.size() > 10) {
    map.fail("systematic_error_m", "1 to 10 polynomial coefficients (ascending powers, metres)",
             std::to_string(c.systematic_error_m.size()) + " coefficients");
  }
  {
    YamlMap noise = map.map("noise");
    c.noise_sigma0_mm = noise.number("sigma0_mm", 0, 1000);
    c.noise_sigma_per_m2_mm = noise.number("sigma_per_m2_mm", 0, 1000);
    noise.finish();
  }
  {
    YamlMap amplitude = map.map("amplitude");
    c.amplitude_at_1m = amplitude.number("at_1m", 1, 32767);
    c.min_valid_amplitude = amplitude.number("min_valid", 0, 32767);
    c.dark_pixel_probability = amplitude.number("dark_pixel_probability", 0, 1);
    amplitude.finish();
  }
  {
    YamlMap mixed = map.map("mixed_pixels");
    c.mixed_pixel_jump_m = mixed.number("jump_m", 1e-3, 100);
    c.mixed_pixel_probability = mixed.number("probability", 0, 1);
    mixed.finish();
  }
  if (map.optional("faults")) {
    for (YamlMap& fault : map.maps("faults")) c.faults.push_back(read_sim_fault(fault));
  }
  if (auto pan_tilt = map.optional_map("pan_tilt")) {
    c.pan_tilt_enabled = true;
    c.pan_amplitude_rad = pan_tilt->number("pan_amplitude_deg", 0, 180) * M_PI / 180.0;
    c.pan_period_s = pan_tilt->number("pan_period_s", 0.1, 1e6);
    c.tilt_amplitude_rad = pan_tilt->number("tilt_amplitude_deg", 0, 90) * M_PI / 180.0;
    c.tilt_period_s = pan_tilt->number("tilt_period_s", 0.1, 1e6);
    pan_tilt->finish();
  }
  for (const SimCameraFaultConfig& f : c.faults) {
    if (f.kind == "pan_tilt_offset" && !c.pan_tilt_enabled) {
      map.fail("faults", "a pan_tilt_offset fault only with camera.sim.pan_tilt (a camera with a pan-tilt head)");
    }
  }
  map.finish();
  return c;
}

void read_channels(YamlMap map, ChannelNames* c) {
  auto name = [&map](const char* key, std::string* out) {
    if (auto v = map.optional_string(key)) *out = *v;
  };
  name("depth", &c->depth);
  name("joint_state", &c->joint_state);
  name("camera_pose", &c->camera_pose);
  name("rendered", &c->rendered);
  name("labels", &c->labels);
  name("discrepancy", &c->discrepancy);
  name("risk", &c->risk);
  name("status", &c->status);
  name("reset", &c->reset);
  name("reset_reply", &c->reset_reply);
  name("heartbeat", &c->heartbeat);
  name("power", &c->power);
  name("motion_estimate", &c->motion_estimate);
  name("planned_trajectory", &c->planned_trajectory);
  name("sim_true_joint_state", &c->sim_true_joint_state);
  name("sim_joint_fault", &c->sim_joint_fault);
  name("sim_camera_fault", &c->sim_camera_fault);
  map.finish();
}

// ---- Safety chain: discrepancy and risk (docs/safety-chain.md) ----

DiscrepancyConfig read_discrepancy(YamlMap map) {
  DiscrepancyConfig d;
  {
    YamlMap noise = map.map("noise");
    d.noise_sigma_at_0m_mm = noise.number("sigma_at_0m_mm", 0, 1000);
    d.noise_sigma_per_m2_mm = noise.number("sigma_per_m2_mm", 0, 1000);
    noise.finish();
  }
  d.tolerance_sigmas = map.number("tolerance_sigmas", 0.5, 100);
  d.model_tolerance_mm = map.number("model_tolerance_mm", 0, 1000);
  d.pair_timeout_ms = map.number("pair_timeout_ms", 1, 10000);
  d.max_pending_frames = static_cast<int>(map.integer("max_pending_frames", 1, 1000));
  d.opening_radius_px = static_cast<int>(map.integer("opening_radius_px", 0, 10));
  d.silhouette_jump_mm = map.number("silhouette_jump_mm", 1, 10000);
  d.near_arm_m = map.number("near_arm_m", 0, 10);
  d.max_depth_mm = map.number("max_depth_mm", 1, 32767);
  {
    YamlMap colour = map.map("colour_image");
    d.colour_image_enabled = colour.boolean("enabled");
    d.colour_image_channel = colour.string("channel");
    d.colour_image_full_scale_mm = colour.number("full_scale_mm", 1, 32767);
    colour.finish();
  }
  map.finish();
  return d;
}

EstimatorConfig read_estimator(YamlMap map) {
  EstimatorConfig e;
  e.estimate_joints = map.boolean("estimate_joints");
  e.estimate_camera = map.boolean("estimate_camera");
  {
    YamlMap warning = map.map("warning");
    e.warning_mismatch_fraction = warning.number("mismatch_fraction", 0, 1);
    e.warning_p95_abs_dis_mm = warning.number("p95_abs_dis_mm", 0, 32767);
    e.warning_min_interval_ms = warning.number("min_interval_ms", 0, 60000);
    warning.finish();
  }
  e.periodic_period_ms = map.number("periodic_period_ms", 10, 3600000);
  e.max_pending_frames = static_cast<int>(map.integer("max_pending_frames", 1, 100));
  e.frames_per_estimate = static_cast<int>(map.integer("frames_per_estimate", 1, e.max_pending_frames));
  e.max_iterations = static_cast<int>(map.integer("max_iterations", 1, 100));
  e.pixel_stride = static_cast<int>(map.integer("pixel_stride", 1, 8));
  map.finish();
  return e;
}

RiskConfig read_risk(YamlMap map) {
  RiskConfig r;
  r.check_period_ms = map.number("check_period_ms", 1, 1000);
  r.debounce_frames = static_cast<int>(map.integer("debounce_frames", 1, 1000));
  r.sensor_debounce_frames = static_cast<int>(map.integer("sensor_debounce_frames", 1, 1000));
  {
    YamlMap deadlines = map.map("deadlines_ms");
    r.depth_deadline_ms = deadlines.number("depth", 1, 60000);
    r.discrepancy_deadline_ms = deadlines.number("discrepancy", 1, 60000);
    r.joint_state_deadline_ms = deadlines.number("joint_state", 1, 60000);
    r.heartbeat_deadline_ms = deadlines.number("heartbeat", 1, 60000);
    deadlines.finish();
  }
  {
    YamlMap pose = map.map("camera_pose");
    r.camera_pose_required = pose.boolean("required");
    r.camera_pose_deadline_ms = pose.number("deadline_ms", 1, 600000);
    pose.finish();
  }
  r.required_heartbeats = map.strings("required_heartbeats");
  {
    YamlMap sensor = map.map("sensor");
    r.max_invalid_fraction = sensor.number("max_invalid_fraction", 0, 1);
    r.calibrated_required = sensor.boolean("calibrated_required");
    r.frozen_repeat_frames = static_cast<int>(sensor.integer("frozen_repeat_frames", 1, 1000));
    r.moving_joint_speed_rad_s = sensor.number("moving_joint_speed_rad_s", 0, 100);
    sensor.finish();
  }
  {
    YamlMap joint = map.map("joint_error");
    r.min_link_pixels = static_cast<int>(joint.integer("min_link_pixels", 1, 1000000));
    r.link_mismatch_fraction = joint.number("link_mismatch_fraction", 0.01, 1);
    r.joint_link_missing_fraction = joint.number("link_missing_fraction", 0.01, 1);
    r.joint_link_affected_fraction = joint.number("link_affected_fraction", 0.001, 1);
    r.joint_link_affected_min_pixels = static_cast<int>(joint.integer("link_affected_min_pixels", 1, 100000));
    joint.finish();
  }
  {
    YamlMap calibration = map.map("calibration_error");
    r.min_environment_pixels = static_cast<int>(calibration.integer("min_environment_pixels", 1, 100000000));
    r.calibration_environment_mismatch_fraction = calibration.number("environment_mismatch_fraction", 0.01, 1);
    r.calibration_robot_link_fraction = calibration.number("robot_link_fraction", 0, 1);
    calibration.finish();
  }
  r.unknown_object_min_area_m2 = map.number("unknown_object_min_area_m2", 1e-6, 100);
  r.unclassified_blob_area_m2 = map.number("unclassified_blob_area_m2", 1e-6, 100);
  {
    YamlMap estimate = map.map("estimate");
    r.estimate_enabled = estimate.boolean("enabled");
    r.estimate_wait_ms = estimate.number("wait_ms", 0, 1000);
    r.estimate_max_age_ms = estimate.number("max_age_ms", 0, 10000);
    r.estimate_sigmas = estimate.number("sigmas", 0, 100);
    r.estimate_min_joint_offset_deg = estimate.number("min_joint_offset_deg", 0, 180);
    r.estimate_min_joint_offset_m = estimate.number("min_joint_offset_m", 0, 10);
    r.estimate_min_translation_m = estimate.number("min_translation_m", 0, 10);
    r.estimate_min_rotation_deg = estimate.number("min_rotation_deg", 0, 180);
    r.estimate_unexplained_residual_mm = estimate.number("unexplained_residual_mm", 0, 10000);
    estimate.finish();
  }
  {
    YamlMap plan = map.map("plan");
    r.plan_enabled = plan.boolean("enabled");
    r.plan_max_deviation_deg = plan.number("max_deviation_deg", 0.01, 180);
    r.plan_max_deviation_m = plan.number("max_deviation_m", 1e-4, 10);
    plan.finish();
  }
  map.finish();
  return r;
}

JointsSimConfig read_joints_sim(YamlMap map) {
  JointsSimConfig sim;
  sim.rate_hz = map.number("rate_hz", 1, 1000);
  sim.status_deadline_ms = map.number("status_deadline_ms", 1, 10000);
  YamlMap motion = map.map("motion");
  for (const auto& joint : motion.keys()) {
    YamlMap m = motion.map(joint);
    JointMotion jm;
    jm.joint = joint;
    jm.center = m.number("center", -100, 100);
    jm.amplitude = m.number("amplitude", 0, 100);
    jm.period_s = m.number("period_s", 0.01, 1e6);
    jm.phase_rad = m.optional_number("phase_rad", 0, -100, 100);
    m.finish();
    sim.motion.push_back(jm);
  }
  motion.finish();
  if (map.optional("faults")) {
    for (auto& f : map.maps("faults")) {
      EncoderFault fault;
      fault.joint = f.string("joint");
      fault.offset = f.number("offset", -100, 100);
      fault.at_s = f.number("at_s", 0, 1e9);
      f.finish();
      sim.faults.push_back(fault);
    }
  }
  {
    YamlMap plan = map.map("plan");
    sim.publish_plan = plan.boolean("publish");
    sim.plan_rate_hz = plan.number("rate_hz", 0.1, 1000);
    sim.plan_horizon_ms = plan.number("horizon_ms", 1, 60000);
    sim.plan_step_ms = plan.number("step_ms", 1, 10000);
    if (sim.plan_step_ms > sim.plan_horizon_ms) plan.fail("step_ms", "a step no longer than horizon_ms");
    plan.finish();
  }
  map.finish();
  return sim;
}

InterventionConfig read_intervention(YamlMap map) {
  InterventionConfig in;
  in.publish_rate_hz = map.number("publish_rate_hz", 10, 1000);
  in.risk_deadline_ms = map.number("risk_deadline_ms", 1, 10000);
  in.stop_deadline_ms = map.number("stop_deadline_ms", 1, 10000);
  in.joint_state_deadline_ms = map.number("joint_state_deadline_ms", 1, 10000);
  in.stopped_velocity = map.number("stopped_velocity", 0, 10);
  in.power_cut = map.choice("power_cut", {"lcm", "usb_hid_relay"});
  if (auto relay = map.optional_map("usb_hid_relay")) {
    in.relay_channel = static_cast<int>(relay->integer("channel", 1, 8));
    in.relay_serial = relay->optional_string("serial").value_or("");
    relay->finish();
  } else if (in.power_cut == "usb_hid_relay") {
    map.fail("usb_hid_relay", "a mapping with channel (and serial) when power_cut is usb_hid_relay");
  }
  map.finish();
  return in;
}

LaunchConfig read_launch(YamlMap map) {
  LaunchConfig launch;
  launch.present = true;
  for (auto& p : map.maps("processes")) {
    LaunchedProcess process;
    process.name = p.string("name");
    process.command = p.strings("command");
    if (process.command.empty()) p.fail("command", "a non-empty list: program and arguments");
    process.required = p.boolean("required");
    p.finish();
    launch.processes.push_back(process);
  }
  launch.restart_backoff_initial_ms = map.number("restart_backoff_initial_ms", 1, 60000);
  launch.restart_backoff_max_ms = map.number("restart_backoff_max_ms", 1, 600000);
  launch.max_restarts = static_cast<int>(map.integer("max_restarts", 0, 1000));
  launch.restart_window_s = map.number("restart_window_s", 1, 86400);
  launch.log_dir = map.path("log_dir");
  YamlMap recorder = map.map("recorder");
  launch.recorder.enabled = recorder.boolean("enabled");
  launch.recorder.max_file_mb = recorder.number("max_file_mb", 0.1, 100000);
  launch.recorder.max_total_mb = recorder.number("max_total_mb", 0.1, 10000000);
  launch.recorder.max_age_h = recorder.number("max_age_h", 0.01, 100000);
  recorder.finish();
  map.finish();
  return launch;
}

}  // namespace

std::string resolve_lcm_url(const std::string& from_config, const char* lcm_default_url_env) {
  if (!from_config.empty()) return from_config;
  if (lcm_default_url_env != nullptr && lcm_default_url_env[0] != '\0') {
    return lcm_default_url_env;
  }
  return kHostLocalLcmUrl;
}

std::string derive_image_url(const std::string& safety_url) {
  static const std::regex udpm(R"(^udpm://([^:/?]+):(\d+)(\?.*)?$)");
  std::smatch m;
  if (!std::regex_match(safety_url, m, udpm)) return safety_url;
  const int port = std::stoi(m[2].str()) + 1;
  std::string options = m[3].str();
  if (options.find("recv_buf_size=") == std::string::npos) {
    options += options.empty() ? "?recv_buf_size=4194304" : "&recv_buf_size=4194304";
  }
  return "udpm://" + m[1].str() + ":" + std::to_string(port) + options;
}

Config default_wire_config(const char* lcm_default_url_env) {
  Config config;
  config.file = "(no config: defaults)";
  config.lcm.url = resolve_lcm_url("", lcm_default_url_env);
  config.lcm.image_url = derive_image_url(config.lcm.url);
  return config;
}

Config load_config(const std::string& path, const char* lcm_default_url_env) {
  YamlMap root = load_yaml_file(path);
  Config config;
  config.file = path;

  std::string url;
  std::string image_url;
  if (auto lcm = root.optional_map("lcm")) {
    url = lcm->optional_string("url").value_or("");
    image_url = lcm->optional_string("image_url").value_or("");
    lcm->finish();
  }
  config.lcm.url = resolve_lcm_url(url, lcm_default_url_env);
  config.lcm.image_url = image_url.empty() ? derive_image_url(config.lcm.url) : image_url;

  if (auto channels = root.optional_map("channels")) read_channels(*channels, &config.channels);

  {
    YamlMap robot = root.map("robot");
    config.robot.id = robot.string("id");
    config.robot.urdf_path = robot.existing_path("urdf");
    if (robot.optional("package_paths")) {
      config.robot.package_paths = robot.existing_paths("package_paths", /*directory=*/true);
    }
    robot.finish();
  }

  if (auto env = root.optional_map("environment")) {
    config.environment.urdf_paths = env->existing_paths("urdfs");
    env->finish();
  }

  {
    YamlMap camera = root.map("camera");
    config.camera.id = camera.string("id");
    config.camera.source = camera.choice("source", {"sim", "uvc"});
    config.camera.rate_hz = camera.number("rate_hz", 0.1, 1000);
    YamlMap intrinsics = camera.map("intrinsics");
    config.camera.intrinsics = read_intrinsics(intrinsics);
    intrinsics.finish();
    config.camera.pose = read_pose(camera.map("pose"));
    if (camera.optional("depth_calibration")) {
      config.camera.depth_calibration = read_depth_calibration(camera.map("depth_calibration"));
    }
    if (config.camera.source == "uvc" || camera.optional("uvc")) {
      config.camera.uvc = read_uvc(camera.map("uvc"));
    }
    if (config.camera.source == "sim" || camera.optional("sim")) {
      config.camera.sim = read_sim(camera.map("sim"));
    }
    camera.finish();
  }

  {
    YamlMap renderer = root.map("renderer");
    config.renderer.geometry = renderer.choice("geometry", {"visual", "collision"});
    config.renderer.padding_m = renderer.number("padding_m", 0, 1);
    config.renderer.near_m = renderer.number("near_m", 1e-3, 100);
    config.renderer.far_m = renderer.number("far_m", 1e-3, 1000);
    if (config.renderer.far_m <= config.renderer.near_m) {
      renderer.fail("far_m", "a distance greater than near_m",
                    std::to_string(config.renderer.far_m));
    }
    config.renderer.max_extrapolation_ms = renderer.number("max_extrapolation_ms", 0, 1000);
    {
      YamlMap poses = renderer.map("camera_pose");
      config.renderer.camera_pose_history_ms = poses.number("history_ms", 10, 60000);
      config.renderer.camera_pose_max_extrapolation_ms = poses.number("max_extrapolation_ms", 0, 1000);
      config.renderer.camera_pose_max_gap_ms = poses.number("max_gap_ms", 1, 10000);
      poses.finish();
    }
    {
      YamlMap prediction = renderer.map("prediction");
      config.renderer.prediction_enabled = prediction.boolean("enabled");
      config.renderer.prediction_joint_tolerance_deg = prediction.number("joint_tolerance_deg", 0, 10);
      config.renderer.prediction_joint_tolerance_m = prediction.number("joint_tolerance_m", 0, 1);
      config.renderer.prediction_pose_tolerance_mm = prediction.number("pose_tolerance_mm", 0, 100);
      config.renderer.prediction_pose_tolerance_deg = prediction.number("pose_tolerance_deg", 0, 10);
      prediction.finish();
    }
    renderer.finish();
  }

  // Safety chain sections (required: no silent defaults for thresholds).
  config.discrepancy = read_discrepancy(root.map("discrepancy"));
  config.risk = read_risk(root.map("risk"));
  config.estimator = read_estimator(root.map("estimator"));
  config.joints_sim = read_joints_sim(root.map("joints_sim"));
  config.intervention = read_intervention(root.map("intervention"));
  if (auto launch = root.optional_map("launch")) config.launch = read_launch(*launch);

  root.finish();
  return config;
}

}  // namespace tofguard
