#include <iostream>
#include <mutex>
#include <optional>

#include "tofguard/camera/camera_sources.hpp"
#include "tofguard/camera/depth_calibration.hpp"
#include "tofguard/camera/uvc_camera.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/lcm_node.hpp"

namespace tofguard::camera {
namespace {

// The newest frame from libuvc's thread, waiting to be published.
struct PendingFrame {
  std::vector<float> depth_m;
  int64_t utime = 0;
  int64_t frame_number = 0;
};

}  // namespace

int run_uvc_camera(const UvcCameraProcessSettings& settings) {
  const CameraSettings& camera_config = settings.camera;
  std::mutex mutex;
  std::optional<PendingFrame> pending;
  int64_t overwritten = 0;  // frames replaced before they were published
  UvcCamera camera(camera_config, settings.uvc,
                   [&](std::vector<float> depth_m, int64_t utime, int64_t number) {
                     std::lock_guard<std::mutex> lock(mutex);
                     if (pending) ++overwritten;
                     pending = PendingFrame{std::move(depth_m), utime, number};
                   });
  std::string message;
  const UvcOpenResult opened = camera.open(&message);
  if (opened != UvcOpenResult::kStreaming) {
    std::cerr << "tofguard-camera: " << message << std::endl;
    return opened == UvcOpenResult::kNoDevice           ? kNoDeviceExitCode
           : opened == UvcOpenResult::kPermissionDenied ? kPermissionDeniedExitCode
                                                        : 1;
  }
  std::cerr << "tofguard-camera: " << message << std::endl;

  LcmNode node(settings.lcm, settings.channels, "tofguard-camera");
  // The frames come as Z (a radial camera's are converted by UvcCamera);
  // the calibration corrects each pixel's distance along its ray.
  const DepthCalibration calibration(settings.depth_calibration.coefficients_m);
  const RadialToZ rays(camera_config.intrinsics);
  const bool calibrated = settings.depth_calibration.enabled;
  const int64_t period_us = static_cast<int64_t>(1e6 / camera_config.rate_hz);
  // No frame for this long: the camera is gone (unplugged, crashed).
  const int64_t lost_after_us = std::max<int64_t>(500000, 5 * period_us);
  const int64_t retry_every_us = 1000000;
  int64_t last_frame_us = monotonic_us();
  int64_t next_retry_us = 0;
  int64_t malformed_counted = 0;
  int64_t overwritten_counted = 0;
  node.heartbeat().set_status("streaming");

  node.add_timer(2000, [&] {
    std::optional<PendingFrame> frame;
    {
      std::lock_guard<std::mutex> lock(mutex);
      frame.swap(pending);
      node.counters().frames_dropped += overwritten - overwritten_counted;
      overwritten_counted = overwritten;
    }
    const int64_t malformed = camera.frames_malformed();
    if (malformed > malformed_counted) {
      node.counters().frames_dropped += malformed - malformed_counted;
      malformed_counted = malformed;
      node.errors().report("uvc", camera.last_error());
    }
    const int64_t now_us = monotonic_us();
    if (frame) {
      node.counters().frames_in++;
      last_frame_us = now_us;
      if (calibrated) calibration.apply_z(&frame->depth_m, rays);
      const depth_image_t image = make_depth_image(camera_config.id, camera_config.intrinsics, frame->utime,
                                                   frame->frame_number, calibrated, frame->depth_m);
      node.images().publish(settings.channels.depth, &image);
      node.counters().frames_out++;
      node.heartbeat().set_last_frame_utime(frame->utime);
    }
    if (camera.is_open() && now_us - last_frame_us > lost_after_us) {
      std::cerr << "tofguard-camera: camera " << camera_config.id << ": no frame for "
                << (now_us - last_frame_us) / 1000 << " ms (unplugged?); reopening every 1 s" << std::endl;
      node.heartbeat().set_status("camera lost: no frames, retrying");
      camera.close();
      next_retry_us = now_us;
    }
    if (!camera.is_open() && now_us >= next_retry_us) {
      std::string why;
      if (camera.open(&why) == UvcOpenResult::kStreaming) {
        std::cerr << "tofguard-camera: camera " << camera_config.id << " is back: " << why << std::endl;
        node.heartbeat().set_status("streaming");
        last_frame_us = monotonic_us();
      } else {
        node.errors().report("uvc-retry", "camera " + camera_config.id + " still lost: " + why);
        next_retry_us = now_us + retry_every_us;
      }
    }
  });
  node.run();
  camera.close();
  return 0;
}

}  // namespace tofguard::camera
