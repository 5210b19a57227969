#pragma once
// The wiring every process shares: the two LCM URLs (config section `lcm`)
// and the channel names (config section `channels`). Read by the
// deployment loader (deployment/config.hpp); LcmNode takes them.
#include <optional>
#include <string>

#include "tofguard/common/yaml_reader.hpp"

namespace tofguard {

// Where the messages go. Small safety messages and depth images travel on
// different multicast ports, so that a watchdog's socket is never flooded by
// depth frames.
struct LcmSettings {
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
  // The authenticated companions of the four channels that can allow motion
  // (authenticated_message_t, docs/security.md): the signed copy of
  // SAFETY_RISK, SAFETY_STATUS and SAFETY_POWER, and the only SAFETY_RESET
  // a keyed tofguard-intervene accepts.
  std::string risk_auth = "SAFETY_RISK_AUTH";
  std::string status_auth = "SAFETY_STATUS_AUTH";
  std::string power_auth = "SAFETY_POWER_AUTH";
  std::string reset_auth = "SAFETY_RESET_AUTH";
  // tofguard-risk's speed limit for the arm's controller (speed_limit_t)
  // and its signed copy: the controller may follow it (speed scaling); it
  // never allows motion that SAFETY_STATUS withdraws.
  std::string speed_limit = "SAFETY_SPEED_LIMIT";
  std::string speed_limit_auth = "SAFETY_SPEED_LIMIT_AUTH";
  // With several cameras: an operator's release of a lost camera
  // (camera_release_t, tofguard-reset --release-camera) to tofguard-risk,
  // its signed companion, and tofguard-risk's answer (reset_reply_t).
  std::string camera_release = "SAFETY_CAMERA_RELEASE";
  std::string camera_release_auth = "SAFETY_CAMERA_RELEASE_AUTH";
  std::string camera_release_reply = "SAFETY_CAMERA_RELEASE_REPLY";
  // tofguard-estimator's joint offsets and camera correction
  // (motion_estimate_t) and the arm controller's plan (planned_trajectory_t).
  std::string motion_estimate = "MOTION_ESTIMATE";
  std::string planned_trajectory = "PLANNED_TRAJECTORY";
  // Simulation only: the simulated arm's true joint state (for the simulated
  // camera) and run-time encoder fault injection.
  std::string sim_true_joint_state = "SIM_TRUE_JOINT_STATE";
  std::string sim_joint_fault = "SIM_JOINT_FAULT";
  std::string sim_controller_fault = "SIM_CONTROLLER_FAULT";
  // Simulation only: run-time fault injection into the simulated camera.
  std::string sim_camera_fault = "SIM_CAMERA_FAULT";
  // What the camera these names belong to appends to its per-camera
  // channels and to its processes' names (heartbeat_t.process): "" for the
  // first camera and for the processes of no camera, "/<camera id>" for
  // every other (camera_channel_names).
  std::string camera_suffix;
};

// One camera's names in a deployment of several: its per-camera channels
// (depth, camera_pose, rendered, labels, discrepancy, motion_estimate,
// sim_camera_fault) are `base`'s with `camera_suffix` appended; the others
// (joint state, risk, status, reset, heartbeat, power, speed limit, plan)
// every camera shares. With camera_suffix "" the names are `base`'s: the
// first camera's channels keep the names a single camera has.
ChannelNames camera_channel_names(const ChannelNames& base, const std::string& camera_suffix);
// The inverse: the names every camera's derive from, from one camera's
// (`camera`'s camera_suffix taken off its per-camera channels).
ChannelNames base_channel_names(const ChannelNames& camera);

// The safety URL: the config's lcm.url, else LCM_DEFAULT_URL, else
// kHostLocalLcmUrl.
constexpr const char* kHostLocalLcmUrl = "udpm://239.255.76.67:7667?ttl=0";
std::string resolve_lcm_url(const std::string& from_config, const char* lcm_default_url_env);

// The image URL when the config names none: for udpm, the same group on the
// next port with recv_buf_size=4194304 (a 176x144..640x480 frame must fit in
// the socket's buffer, or it is silently lost); other providers unchanged.
std::string derive_image_url(const std::string& safety_url);

// "" when `url` keeps the bus on this host, else one loud line saying how it
// opens it: udpm with ttl > 0 (multicast routed beyond the host), or tcpq to
// another host. memq, file and udpm with ttl=0 (LCM's default) stay local.
std::string bus_exposure_warning(const std::string& url);

// The optional `lcm` section (url, image_url; both optional), resolved as
// above. `lcm_default_url_env` is the value of LCM_DEFAULT_URL (nullptr when
// unset).
LcmSettings read_lcm_settings(std::optional<YamlMap> section, const char* lcm_default_url_env);

// The optional `channels` section: each key renames one channel.
ChannelNames read_channel_names(YamlMap section);

}  // namespace tofguard
