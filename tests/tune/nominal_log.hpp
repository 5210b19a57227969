#pragma once
// LCM logs of the simulated camera and arm written in-process with
// lcm::LogFile (no network), as scripts/record-scenario records them: the
// camera's TOF_DEPTH frames (the URDF rendered at the true joints by the EGL
// renderer, the config's ToF error model and distance calibration:
// SimulatedFrames) at camera.rate_hz, each published one frame period after
// its capture like tofguard-camera's sim source, and JOINT_STATE at 100 Hz
// (joints_sim.motion's sinusoids), in publication order. For tofguard-tune's
// tests.
#include <lcm/lcm-cpp.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "log_events.hpp"
#include "simulated_frames.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/joint_state_t.hpp"

namespace tofguard::test {

struct NominalLogOptions {
  double seconds = 10;        // of camera frames
  double lead_in_s = 0.5;     // joint states before the first frame (lcm-logplayer may drop the start)
  double motion_start_s = 0;  // motion time at the log's start: another stretch of the motion
  uint64_t noise_seed = 1;    // frame k's noise: frame index noise_seed * 1e6 + k
  bool still = false;         // the arm holds its centre pose
  double joint_rate_hz = 100;
  std::vector<renderer::ExtraObject> objects;  // in view throughout (not nominal)
  // Faults throughout (not nominal): the true camera moved by
  // `camera_offset` (in its optical frame: true = configured * offset), and
  // each joint of `encoder_offset_rad` reported that much more than it is.
  Eigen::Isometry3d camera_offset = Eigen::Isometry3d::Identity();
  std::map<std::string, double> encoder_offset_rad;
  // A drift of the camera's distances after commissioning: every distance
  // read this much farther along its ray, mm.
  double distance_offset_mm = 0;
};

// Every valid Z of `depth_m` moved `offset_mm` farther along its pixel's
// ray: Z + offset f, f = Z / r = 1 / sqrt(1 + x^2 + y^2).
inline void add_distance_offset(const Intrinsics& in, double offset_mm, std::vector<float>* depth_m) {
  if (offset_mm == 0) return;
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      float& z = (*depth_m)[static_cast<size_t>(v) * in.width + u];
      const double x = (u - in.cx) / in.fx, y = (v - in.cy) / in.fy;
      if (z > 0) z += static_cast<float>(offset_mm * 1e-3 / std::sqrt(1 + x * x + y * y));
    }
  }
}

// Writes the log to `path`; returns the number of camera frames.
inline int write_nominal_log(const std::string& path, const deployment::Config& config,
                             const NominalLogOptions& options) {
  std::filesystem::remove(path);
  lcm::LogFile log(path, "w");
  if (!log.good()) throw std::runtime_error(path + ": cannot write");
  SimulatedFrames camera(config);
  const Eigen::Isometry3d pose = config.camera.pose.frame_from_optical() * options.camera_offset;
  const int64_t base_utime = 1'700'000'000'000'000;
  const auto period_us = static_cast<int64_t>(std::llround(1e6 / config.camera.rate_hz));
  const auto joint_period_us = static_cast<int64_t>(std::llround(1e6 / options.joint_rate_hz));
  const auto lead_in_us = static_cast<int64_t>(std::llround(options.lead_in_s * 1e6));
  const int frames = static_cast<int>(std::floor(options.seconds * config.camera.rate_hz));
  auto joints_at = [&](int64_t utime) {
    const double t_s = options.motion_start_s + (utime - base_utime) * 1e-6;
    robot_model::JointPositions q;
    for (const sim::JointMotion& m : config.joints_sim.motion) {
      q[m.joint] = m.center +
                   (options.still ? 0.0 : m.amplitude * std::sin(2 * M_PI * t_s / m.period_s + m.phase_rad));
    }
    return q;
  };
  // Publication times: joint state j at its utime, frame k one period after
  // its capture; joint states first at equal times.
  const int64_t end_us = lead_in_us + frames * period_us + period_us;
  int next_frame = 0;
  for (int64_t t = 0; t <= end_us; t += joint_period_us) {
    while (next_frame < frames && lead_in_us + next_frame * period_us + period_us <= t) {
      const int64_t capture = base_utime + lead_in_us + next_frame * period_us;
      std::vector<float> depth_m =
          camera.capture(joints_at(capture), pose, config.camera.intrinsics,
                         options.noise_seed * 1'000'000 + static_cast<uint64_t>(next_frame), options.objects);
      add_distance_offset(config.camera.intrinsics, options.distance_offset_mm, &depth_m);
      const depth_image_t frame = make_depth_image(config.camera.id, config.camera.intrinsics, capture,
                                                   next_frame, /*calibrated=*/true, depth_m);
      write_log_event(&log, capture + period_us, config.channels.depth, frame);
      ++next_frame;
    }
    joint_state_t state{};
    state.utime = base_utime + t;
    state.robot_id = config.robot.id;
    const double t_s = options.motion_start_s + t * 1e-6;
    for (const sim::JointMotion& m : config.joints_sim.motion) {
      const double w = 2 * M_PI / m.period_s;
      state.name.push_back(m.joint);
      const auto offset = options.encoder_offset_rad.find(m.joint);
      state.position.push_back(m.center +
                               (options.still ? 0.0 : m.amplitude * std::sin(w * t_s + m.phase_rad)) +
                               (offset == options.encoder_offset_rad.end() ? 0.0 : offset->second));
      state.velocity.push_back(options.still ? 0.0 : m.amplitude * w * std::cos(w * t_s + m.phase_rad));
    }
    state.num_joints = static_cast<int32_t>(state.name.size());
    write_log_event(&log, state.utime, config.channels.joint_state, state);
  }
  return frames;
}

}  // namespace tofguard::test
