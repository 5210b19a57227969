#pragma once
// tofguard-camera's USB source (the simulated one is tofguard/sim/sim_camera_runner.hpp), publishing
// depth_image_t on channels.depth (image URL) at camera.rate_hz with the distance calibration applied, and a
// heartbeat whose frames_dropped counts every frame that was lost or late.
#include "tofguard/settings/depth_camera_settings.hpp"

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
int run_uvc_camera(const UvcCameraProcessSettings& settings);

}  // namespace tofguard::camera
