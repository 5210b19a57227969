#pragma once
// Power-cut actuators. Both are positive logic: the arm's power flows only
// while the actuator is actively told "enabled".
//
// - `lcm`: power_relay_t on SAFETY_POWER (see lcmtypes/power_relay_t.lcm),
//   for a power controller that listens to LCM with its own deadline.
// - `usb_hid_relay`: the common USB HID relay boards (16c0:05df, "USBRelayN")
//   through libusb. Wire the arm's power through the relay's normally-open
//   contact, so that power flows only while the relay is held on.
//   Limitation: these boards have no watchdog; if tofguard-intervene dies
//   with SIGKILL the relay stays where it was. The controller's deadline on
//   SAFETY_STATUS stays the primary stop; the relay is the second channel.
// - `serial_pulse` (serial_pulse_output.hpp): a pulse train for a hardware
//   watchdog, which survives this process's death (docs/intervene.md).
#include <array>
#include <cstdint>
#include <memory>
#include <string>

struct libusb_context;
struct libusb_device_handle;

namespace tofguard::intervene {

class PowerActuator {
 public:
  virtual ~PowerActuator() = default;
  // Commands the power; returns "" on success, else one line saying what
  // failed (the caller keeps the arm stopped and reports it).
  virtual std::string set_power(bool enabled, const std::string& reason) = 0;
};

// The 8-byte HID feature report that switches relay `channel` (1-based) of a
// 16c0:05df board: 0xFF = on, 0xFD = off, then the channel number.
std::array<uint8_t, 8> hid_relay_report(int channel, bool on);
// Whether relay `channel` is on in the board's state report (byte 7 is a bit
// mask, bit channel-1).
bool hid_relay_is_on(const std::array<uint8_t, 8>& state_report, int channel);

constexpr uint16_t kHidRelayVendorId = 0x16c0;
constexpr uint16_t kHidRelayProductId = 0x05df;

class UsbHidRelay : public PowerActuator {
 public:
  // Finds the board (by serial, or the only one when serial is ""); a
  // missing board is not an exception: set_power() then reports the error
  // and retries opening it on every call.
  UsbHidRelay(int channel, std::string serial);
  ~UsbHidRelay() override;
  std::string set_power(bool enabled, const std::string& reason) override;

 private:
  std::string open();
  void close();

  int channel_;
  std::string serial_;
  libusb_context* usb_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
};

}  // namespace tofguard::intervene
