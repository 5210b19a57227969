#pragma once
// A dynamic (pulsed) power output: a square wave on a USB serial
// adapter's line for a retriggerable hardware watchdog or a safety relay
// with a dynamic input, which keeps the arm's power on only while the pulses
// come. Unlike a relay held on (usb_hid_relay), it survives tofguard-
// intervene's own death: kill -9, a hang or a crash stops the pulses, and
// the watchdog drops the power within its period. Wiring:
// docs/intervene.md.
//
// Lines:
//   dtr, rts - the modem control line toggles every half period (TIOCMBIS /
//              TIOCMBIC), held low while the power is off;
//   tx       - one byte 0x55 per period on the data line (a charge pump or
//              a watchdog retriggered by serial data), none while off.
//
// The pulses come from the caller's loop (half_period_tick, from
// tofguard-intervene's own event loop), never from a thread of their own: a
// hung loop must stop them.
#include <cstdint>
#include <string>

#include "tofguard/intervene/power_actuator.hpp"
#include "tofguard/settings/intervene_settings.hpp"

namespace tofguard::intervene {

// "dtr", "rts", "tx".
std::string pulse_line_name(PulseLine line);

class SerialPulseOutput : public PowerActuator {
 public:
  // Opens the device on first use; a missing device is not an exception:
  // set_power() and half_period_tick() report it and retry.
  explicit SerialPulseOutput(SerialPulseSettings settings);
  ~SerialPulseOutput() override;
  SerialPulseOutput(const SerialPulseOutput&) = delete;
  SerialPulseOutput& operator=(const SerialPulseOutput&) = delete;

  // Power on: the pulses run from the next tick. Power off: the line is
  // driven low at once and the pulses stop. "" or one line saying what
  // failed.
  std::string set_power(bool enabled, const std::string& reason) override;
  // The next half period: toggles the line while the power is on. "" or one
  // line saying what failed.
  std::string half_period_tick();
  // Half the pulse period, microseconds (the tick interval).
  int64_t half_period_us() const;
  // Pulses (rising edges, or bytes on tx) sent so far.
  int64_t pulses() const { return pulses_; }

 private:
  std::string open();
  void close();
  std::string drive(bool high);

  SerialPulseSettings settings_;
  int fd_ = -1;
  bool enabled_ = false;
  bool high_ = false;
  int64_t pulses_ = 0;
};

}  // namespace tofguard::intervene
