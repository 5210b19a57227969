#include "tofguard/settings/sim_settings.hpp"

#include <cmath>

namespace tofguard::settings {
namespace {

Eigen::Vector3d vector3(YamlMap& map, const std::string& key, double limit) {
  const auto v = map.numbers(key, 3);
  for (double x : v) {
    if (std::abs(x) > limit) {
      map.fail(key, "3 numbers each in [-" + std::to_string(limit) + ", " + std::to_string(limit) + "]",
               std::to_string(x));
    }
  }
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

SimCameraFaultSettings read_sim_fault(YamlMap map) {
  SimCameraFaultSettings f;
  f.kind = map.choice("kind", {"frozen_image", "stall", "pose_drift", "intruding_object", "pan_tilt_offset"});
  f.start_us = map.seconds_as_us("start_s", 0, 1e6);
  f.duration_us = map.seconds_as_us("duration_s", 0, 1e6);
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

// camera.sim.residual: every key of the error required (a partial truth of
// the simulated camera is more likely a typo than a wish); only the camera's
// time on before the process started is optional.
SimResidualSettings read_sim_residual(YamlMap map) {
  SimResidualSettings r;
  r.wiggle_amplitude_mm = map.number("wiggle_amplitude_mm", 0, 100);
  r.wiggle_period_m = map.number("wiggle_period_m", 0.1, 100);
  r.wiggle_phase_rad = map.number("wiggle_phase_rad", -2 * M_PI, 2 * M_PI);
  r.slope_mm_per_m = map.number("slope_mm_per_m", -100, 100);
  r.pixel_offset_sigma_mm = map.number("pixel_offset_sigma_mm", 0, 100);
  r.reflectivity_bias_mm_per_decade = map.number("reflectivity_bias_mm_per_decade", -100, 100);
  r.reference_amplitude = map.number("reference_amplitude", 1, 32767);
  r.multipath_max_mm = map.number("multipath_max_mm", 0, 200);
  r.warmup_drift_mm = map.number("warmup_drift_mm", -100, 100);
  r.warmup_time_constant_s = map.number("warmup_time_constant_s", 1, 86400);
  if (map.optional("on_before_start_s")) r.on_before_start_s = map.number("on_before_start_s", 0, 1e7);
  map.finish();
  return r;
}

SimUserSettings read_sim_user(YamlMap map) {
  SimUserSettings u;
  u.urdf_path = map.existing_path("urdf");
  u.seated_on = map.string("seated_on");
  u.breathing_mm = map.number("breathing_mm", 0, 100);
  u.breathing_period_s = map.number("breathing_period_s", 0.1, 1e6);
  u.head_turn_rad = map.number("head_turn_deg", 0, 90) * M_PI / 180.0;
  u.head_period_s = map.number("head_period_s", 0.1, 1e6);
  u.hand_motion_m = map.number("hand_motion_m", 0, 1);
  u.hand_period_s = map.number("hand_period_s", 0.1, 1e6);
  map.finish();
  return u;
}

}  // namespace

SimCameraSettings read_sim_camera_settings(YamlMap map) {
  SimCameraSettings c;
  c.seed = static_cast<uint64_t>(map.integer("seed", 0, INT64_MAX));
  if (map.optional("exposure_offset_ms")) c.exposure_offset_ms = map.number("exposure_offset_ms", 0, 1000);
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
  if (auto residual = map.optional_map("residual")) c.residual = read_sim_residual(*residual);
  if (map.optional("faults")) {
    for (YamlMap& fault : map.maps("faults")) c.faults.push_back(read_sim_fault(fault));
  }
  if (auto user = map.optional_map("user")) c.user = read_sim_user(*user);
  if (auto pan_tilt = map.optional_map("pan_tilt")) {
    c.pan_tilt_enabled = true;
    c.pan_amplitude_rad = pan_tilt->number("pan_amplitude_deg", 0, 180) * M_PI / 180.0;
    c.pan_period_s = pan_tilt->number("pan_period_s", 0.1, 1e6);
    c.tilt_amplitude_rad = pan_tilt->number("tilt_amplitude_deg", 0, 90) * M_PI / 180.0;
    c.tilt_period_s = pan_tilt->number("tilt_period_s", 0.1, 1e6);
    pan_tilt->finish();
  }
  for (const SimCameraFaultSettings& f : c.faults) {
    if (f.kind == "pan_tilt_offset" && !c.pan_tilt_enabled) {
      map.fail("faults",
               "a pan_tilt_offset fault only with camera.sim.pan_tilt (a camera with a pan-tilt head)");
    }
  }
  map.finish();
  return c;
}

JointsSimSettings read_joints_sim_settings(YamlMap map) {
  JointsSimSettings sim;
  sim.rate_hz = map.number("rate_hz", 1, 1000);
  sim.status_deadline_us = map.milliseconds_as_us("status_deadline_ms", 1, 10000);
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
  if (auto task = map.optional_map("task")) {
    sim.task_move_s = task->number("move_s", 0.1, 1e4);
    for (YamlMap& w : task->maps("waypoints")) {
      TaskWaypoint waypoint;
      waypoint.name = w.string("name");
      waypoint.hold_s = w.number("hold_s", 0, 1e4);
      YamlMap joints = w.map("joints");
      for (const auto& joint : joints.keys()) waypoint.joints[joint] = joints.number(joint, -100, 100);
      joints.finish();
      w.finish();
      sim.task_waypoints.push_back(waypoint);
    }
    if (sim.task_waypoints.size() < 2)
      task->fail("waypoints", "at least two waypoints (a task goes somewhere)");
    task->finish();
  }
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
    sim.plan_horizon_us = plan.milliseconds_as_us("horizon_ms", 1, 60000);
    sim.plan_step_us = plan.milliseconds_as_us("step_ms", 1, 10000);
    if (sim.plan_step_us > sim.plan_horizon_us) plan.fail("step_ms", "a step no longer than horizon_ms");
    plan.finish();
  }
  if (auto follow = map.optional_map("follow_speed_limit")) {
    sim.follow_speed_limit = true;
    sim.speed_limit_margin = follow->number("margin", 0.1, 1);
    sim.speed_ramp_per_s = follow->number("ramp_per_s", 0.01, 100);
    follow->finish();
  }
  map.finish();
  return sim;
}

}  // namespace tofguard::settings
