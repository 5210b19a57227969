// The UVC source without hardware: with no matching camera attached,
// tofguard-camera says so in one line that lists the USB devices found,
// and exits 3 before publishing anything.
#include "tofguard/camera/uvc_camera.hpp"

#include <algorithm>

#include <gtest/gtest.h>

#include "tofguard/camera/camera_sources.hpp"
#include "tool_support.hpp"

namespace tofguard::camera {
namespace {

// config/sim.yaml turned into a uvc camera config for ids nobody uses.
std::string uvc_config() {
  return test::sim_config_variant(
      "uvc_camera", {{"source: sim",
                      "source: uvc\n  uvc: {vendor_id: \"fffe\", product_id: \"fffd\", serial: \"X1\", "
                      "format: z16, depth_unit_mm: 0.125, distance: radial}"}});
}

TEST(UvcCamera, ListsUsbDevicesInOneLine) {
  const std::string line = list_usb_devices();
  EXPECT_TRUE(line.rfind("USB devices found:", 0) == 0 ||
              line.rfind("cannot list USB devices: libusb: ", 0) == 0)
      << line;
  EXPECT_EQ(line.find('\n'), std::string::npos) << line;
}

TEST(UvcCamera, NoMatchingDeviceIsOneLineAndExitCode3) {
  std::string out, err;
  const int rc = test::run_command(
      "camera_no_device", {test::bin_dir() + "/tofguard-camera", "--config", uvc_config()}, &out, &err);
  EXPECT_EQ(rc, kNoDeviceExitCode) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_EQ(err.rfind("tofguard-camera: no UVC camera fffe:fffd serial X1 attached; ", 0), 0u) << err;
  EXPECT_TRUE(err.find("USB devices found:") != std::string::npos ||
              err.find("cannot list USB devices") != std::string::npos)
      << err;
}

TEST(UvcCamera, UdevRuleShippedWhereTheMessageSays) {
  const std::string rule = test::read_file(test::source_dir() + "/" + kUdevRule);
  EXPECT_NE(rule.find("ID_USB_INTERFACES}==\"*:0e02??:*\""), std::string::npos);
}

}  // namespace
}  // namespace tofguard::camera
