#include <libusb.h>

#include <cstring>
#include <vector>

#include "tofguard/intervene/power_actuator.hpp"

namespace tofguard::intervene {
namespace {

constexpr uint8_t kSetReport = 0x09;
constexpr uint8_t kGetReport = 0x01;
constexpr uint16_t kFeatureReport0 = 0x0300;
constexpr unsigned kTimeoutMs = 200;

std::string usb_error(const char* what, int code) {
  return std::string(what) + ": " + libusb_strerror(static_cast<libusb_error>(code));
}

}  // namespace

std::array<uint8_t, 8> hid_relay_report(int channel, bool on) {
  std::array<uint8_t, 8> report{};
  report[0] = on ? 0xFF : 0xFD;
  report[1] = static_cast<uint8_t>(channel);
  return report;
}

bool hid_relay_is_on(const std::array<uint8_t, 8>& state_report, int channel) {
  return (state_report[7] >> (channel - 1)) & 1;
}

UsbHidRelay::UsbHidRelay(int channel, std::string serial) : channel_(channel), serial_(std::move(serial)) {
  if (libusb_init(&usb_) != 0) usb_ = nullptr;
}

UsbHidRelay::~UsbHidRelay() {
  if (handle_) set_power(false, "tofguard-intervene exiting");
  close();
  if (usb_) libusb_exit(usb_);
}

void UsbHidRelay::close() {
  if (handle_) {
    libusb_release_interface(handle_, 0);
    libusb_close(handle_);
    handle_ = nullptr;
  }
}

std::string UsbHidRelay::open() {
  if (!usb_) return "USB HID relay: libusb could not be initialised";
  libusb_device** devices = nullptr;
  const ssize_t count = libusb_get_device_list(usb_, &devices);
  if (count < 0) return usb_error("USB HID relay: cannot list USB devices", static_cast<int>(count));
  std::vector<libusb_device_handle*> boards;
  std::string problem;
  for (ssize_t i = 0; i < count; ++i) {
    libusb_device_descriptor descriptor;
    if (libusb_get_device_descriptor(devices[i], &descriptor) != 0) continue;
    if (descriptor.idVendor != kHidRelayVendorId || descriptor.idProduct != kHidRelayProductId) continue;
    libusb_device_handle* handle = nullptr;
    const int r = libusb_open(devices[i], &handle);
    if (r != 0) {
      problem = r == LIBUSB_ERROR_ACCESS ? "USB HID relay 16c0:05df: permission denied (install "
                                           "scripts/udev/99-tofguard-relay.rules into /etc/udev/rules.d/)"
                                         : usb_error("USB HID relay 16c0:05df: cannot open", r);
      continue;
    }
    if (!serial_.empty()) {
      std::array<uint8_t, 8> state{};
      const int n = libusb_control_transfer(
          handle, LIBUSB_ENDPOINT_IN | LIBUSB_REQUEST_TYPE_CLASS | LIBUSB_RECIPIENT_INTERFACE, kGetReport,
          kFeatureReport0, 0, state.data(), state.size(), kTimeoutMs);
      // The board's serial is the first five bytes of its state report.
      if (n < 5 || std::string(reinterpret_cast<char*>(state.data()),
                               strnlen(reinterpret_cast<char*>(state.data()), 5)) != serial_) {
        libusb_close(handle);
        continue;
      }
    }
    boards.push_back(handle);
  }
  libusb_free_device_list(devices, 1);
  if (boards.size() != 1) {
    for (auto* h : boards) libusb_close(h);
    if (boards.empty()) {
      return problem.empty()
                 ? "USB HID relay 16c0:05df" + (serial_.empty() ? std::string() : " with serial " + serial_) +
                       " not found"
                 : problem;
    }
    return "USB HID relay: " + std::to_string(boards.size()) +
           " boards 16c0:05df found: set intervention.usb_hid_relay.serial";
  }
  handle_ = boards[0];
  libusb_set_auto_detach_kernel_driver(handle_, 1);
  const int r = libusb_claim_interface(handle_, 0);
  if (r != 0) {
    close();
    return usb_error("USB HID relay: cannot claim its interface", r);
  }
  return "";
}

std::string UsbHidRelay::set_power(bool enabled, const std::string&) {
  if (!handle_) {
    const std::string error = open();
    if (!error.empty()) return error;
  }
  auto report = hid_relay_report(channel_, enabled);
  int r = libusb_control_transfer(
      handle_, LIBUSB_ENDPOINT_OUT | LIBUSB_REQUEST_TYPE_CLASS | LIBUSB_RECIPIENT_INTERFACE, kSetReport,
      kFeatureReport0, 0, report.data(), report.size(), kTimeoutMs);
  if (r < 0) {
    close();  // unplugged or broken: reopen next time
    return usb_error("USB HID relay: cannot switch the relay", r);
  }
  // Read the state back: the command only counts when the board confirms it.
  std::array<uint8_t, 8> state{};
  r = libusb_control_transfer(handle_,
                              LIBUSB_ENDPOINT_IN | LIBUSB_REQUEST_TYPE_CLASS | LIBUSB_RECIPIENT_INTERFACE,
                              kGetReport, kFeatureReport0, 0, state.data(), state.size(), kTimeoutMs);
  if (r < 8) {
    close();
    return r < 0 ? usb_error("USB HID relay: cannot read the relay state", r)
                 : "USB HID relay: short state report";
  }
  if (hid_relay_is_on(state, channel_) != enabled) {
    return "USB HID relay: relay " + std::to_string(channel_) + " did not switch " + (enabled ? "on" : "off");
  }
  return "";
}

}  // namespace tofguard::intervene
