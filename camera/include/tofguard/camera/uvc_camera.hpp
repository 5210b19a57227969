#pragma once
// A USB Video Class depth camera through libuvc (on libusb): finds the
// configured camera by vendor:product[:serial], negotiates the configured
// 16-bit format, size and rate, and hands every complete frame, converted
// to Z in metres, to a callback.
//
// libuvc assembles the payloads itself (it does not expose them), so the
// checks of uvc_payload.hpp that can still be made on its frames are made
// here: a frame of the wrong size or shape is dropped and counted.
//
// Timing: libuvc stamps a frame when its last payload arrives (wall clock),
// so utime is the end of the transfer, not mid-exposure: it lags the
// exposure by about one frame period plus the USB latency.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "tofguard/camera/depth_conversion.hpp"
#include "tofguard/settings/depth_camera_settings.hpp"

struct uvc_context;
struct uvc_device;
struct uvc_device_handle;
struct uvc_frame;

namespace tofguard::camera {

// Where the udev rule that gives users access to the camera is shipped.
constexpr const char* kUdevRule = "scripts/udev/99-tofguard-camera.rules";

// One line listing the USB devices libusb sees ("vendor:product name, ..."),
// or saying why they cannot be listed.
std::string list_usb_devices();

enum class UvcOpenResult { kStreaming, kNoDevice, kPermissionDenied, kFailed };

class UvcCamera {
 public:
  // A frame: Z in metres (0 = invalid, not yet calibrated), capture time,
  // and its number among all frames libuvc delivered since construction
  // (malformed ones included, so a dropped frame leaves a gap).
  using FrameHandler = std::function<void(std::vector<float> depth_m, int64_t utime, int64_t frame_number)>;

  // `on_frame` is called on libuvc's thread.
  UvcCamera(const CameraSettings& camera, const UvcSettings& uvc, FrameHandler on_frame);
  ~UvcCamera();
  UvcCamera(const UvcCamera&) = delete;
  UvcCamera& operator=(const UvcCamera&) = delete;

  // Finds, opens and starts the camera. On failure `*message` is one line:
  // for kNoDevice it lists the USB devices found, for kPermissionDenied it
  // names the udev rule to install.
  UvcOpenResult open(std::string* message);
  // Stops streaming and releases the camera (for a retry after an unplug).
  void close();
  bool is_open() const { return handle_ != nullptr; }

  // Frames libuvc delivered with the wrong size or shape (dropped).
  int64_t frames_malformed() const { return frames_malformed_.load(); }
  // The last malformed frame's reason ("" if none).
  std::string last_error() const;

 private:
  static void frame_callback(uvc_frame* frame, void* self);
  void on_uvc_frame(const uvc_frame& frame);
  std::string device_name() const;

  CameraSettings camera_;
  UvcSettings uvc_;
  RawDepthFormat format_;
  RadialToZ radial_to_z_;
  FrameHandler on_frame_;
  uvc_context* context_ = nullptr;
  uvc_device* device_ = nullptr;
  uvc_device_handle* handle_ = nullptr;
  std::atomic<int64_t> frames_malformed_{0};
  int64_t frames_seen_ = 0;  // only touched on libuvc's thread
  mutable std::mutex error_mutex_;
  std::string last_error_;
};

}  // namespace tofguard::camera
