#pragma once
// The real camera drivers' settings (config section `camera`: uvc,
// depth_calibration); the camera every process shares (id, rate,
// intrinsics, pose) is common's CameraSettings, the simulated camera's
// (camera.sim) is in sim/.
#include <string>
#include <vector>

#include "tofguard/common/camera_settings.hpp"
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/yaml_reader.hpp"

namespace tofguard::settings {

// camera.depth_calibration: distance calibration applied by tofguard-camera
// before publishing:
//   d_calibrated = d - p(d),  p(d) = sum_i coefficients_m[i] * d^i,
// with d the measured distance along the pixel's ray (radial, not Z) in
// metres and p(d) in metres; a Z image is corrected per pixel through its
// ray (camera/include/tofguard/camera/depth_calibration.hpp). Fitted by
// tofguard-calibrate-depth.
struct DepthCalibrationSettings {
  // false when the config has no camera.depth_calibration: frames are then
  // published with calibrated = false.
  bool enabled = false;
  int degree = 0;
  // degree + 1 coefficients, ascending powers of d.
  std::vector<double> coefficients_m;
};

// A USB Video Class depth camera (camera.uvc, required when source is uvc).
struct UvcSettings {
  int vendor_id = 0;   // vendor_id: USB idVendor (written as 4 hex digits in the YAML)
  int product_id = 0;  // product_id: USB idProduct
  // serial: the camera's USB serial number; "" accepts any camera with
  // these ids.
  std::string serial;
  // format: stream format, one little-endian 16-bit count per pixel: "z16",
  // "y16" or "gray16" (y16 and gray16 are the same UVC format GUID).
  std::string format;
  // depth_unit_mm: millimetres per count (e.g. 1.0, 0.25, 0.125).
  double depth_unit_mm = 0;
  // distance (z or radial): true when the camera reports radial distance
  // along each pixel's ray (converted to Z with the intrinsics), false when
  // it reports Z.
  bool radial_distance = false;
};

// Read (and finish) camera.depth_calibration and camera.uvc.
DepthCalibrationSettings read_depth_calibration_settings(YamlMap section);
UvcSettings read_uvc_settings(YamlMap section);

// Everything tofguard-camera needs with camera.source uvc.
struct UvcCameraProcessSettings {
  LcmSettings lcm;
  ChannelNames channels;
  CameraSettings camera;
  DepthCalibrationSettings depth_calibration;
  UvcSettings uvc;
};

}  // namespace tofguard::settings

// The component's own names for its settings (tofguard::camera::DepthCalibrationSettings, ...).
namespace tofguard::camera {
using settings::DepthCalibrationSettings;
using settings::read_depth_calibration_settings;
using settings::read_uvc_settings;
using settings::UvcCameraProcessSettings;
using settings::UvcSettings;
}  // namespace tofguard::camera
