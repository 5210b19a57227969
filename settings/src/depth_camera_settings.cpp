#include "tofguard/settings/depth_camera_settings.hpp"

#include <regex>

namespace tofguard::settings {
namespace {

int read_usb_id(YamlMap& map, const std::string& key) {
  static const std::regex hex4("^[0-9a-fA-F]{4}$");
  const std::string text = map.string(key);
  if (!std::regex_match(text, hex4)) {
    map.fail(key, "a USB id as 4 hex digits in quotes, as lsusb shows it (e.g. \"2bc5\")",
             "\"" + text + "\"");
  }
  return std::stoi(text, nullptr, 16);
}

}  // namespace

DepthCalibrationSettings read_depth_calibration_settings(YamlMap map) {
  DepthCalibrationSettings c;
  c.enabled = true;
  c.degree = static_cast<int>(map.integer("degree", 0, 9));
  c.coefficients_m = map.numbers("coefficients_m", c.degree + 1);
  map.finish();
  return c;
}

UvcSettings read_uvc_settings(YamlMap map) {
  UvcSettings c;
  c.vendor_id = read_usb_id(map, "vendor_id");
  c.product_id = read_usb_id(map, "product_id");
  c.serial = map.optional_string("serial").value_or("");
  c.format = map.choice("format", {"z16", "y16", "gray16"});
  c.depth_unit_mm = map.number("depth_unit_mm", 1e-3, 100);
  c.radial_distance = map.choice("distance", {"z", "radial"}) == "radial";
  map.finish();
  return c;
}

}  // namespace tofguard::settings
