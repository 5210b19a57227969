#pragma once
// tofguard-camera's two sources, each publishing depth_image_t on
// channels.depth (image URL) at camera.rate_hz with the distance
// calibration applied, and a heartbeat whose frames_dropped counts every
// frame that was lost or late.
#include "tofguard/config.hpp"

namespace tofguard::camera {

// Exit codes of tofguard-camera besides 0 (stopped by a signal), 1 (other
// failure) and 2 (config error).
constexpr int kNoDeviceExitCode = 3;
constexpr int kPermissionDeniedExitCode = 4;

// camera.source == "uvc": opens the camera before anything is published
// (no matching device: one line listing the USB devices found, exit 3;
// permission denied: one line naming the udev rule, exit 4). A camera that
// stops sending frames (unplugged) is reported, closed and reopened every
// second until it is back; meanwhile nothing is published, so the risk
// chain sees stale depth and stops the arm.
int run_uvc_camera(const Config& config);

}  // namespace tofguard::camera

namespace tofguard::camera {

// camera.source == "sim": renders the scene of the config (robot and
// environment URDFs, visual geometry, unpadded) at the simulated arm's true
// joint state from channels.sim_true_joint_state, applies the ToF error
// model and the distance calibration, and publishes at camera.rate_hz.
// Faults come from camera.sim.faults and from sim_camera_fault_t on
// channels.sim_camera_fault. A frame that cannot be made (no recent true
// joint state, render failure, stall fault) or whose slot was missed
// because the process was late is counted in frames_dropped; seq counts
// frame slots, so a lost frame leaves a gap in seq.
int run_sim_camera(const Config& config);

}  // namespace tofguard::camera
