#pragma once
// tofguard-intervene's settings (config section `intervention`,
// docs/safety-chain.md). Durations are integer microseconds, converted once
// when the file is read, so that the deadlines compare integers on the
// monotonic clock.
#include <cstdint>
#include <string>

#include "tofguard/auth/auth_settings.hpp"
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/yaml_reader.hpp"

namespace tofguard::settings {

// The serial pulse output's line (serial_pulse_output.hpp, docs/intervene.md).
enum class PulseLine { kDtr, kRts, kTx };

// `intervention.serial_pulse`: the pulse train for a hardware watchdog.
struct SerialPulseSettings {
  std::string device;  // e.g. /dev/ttyUSB0
  PulseLine line = PulseLine::kDtr;
  double frequency_hz = 0;  // pulses per second, > 0
};

struct InterveneSettings {
  // publish_rate_hz: SAFETY_STATUS rate; a change is published at once as
  // well.
  double publish_rate_hz = 0;
  // risk_deadline_ms: no SAFETY_RISK for this long (monotonic) -> power
  // cut; microseconds.
  int64_t risk_deadline_us = 0;
  // stop_deadline_ms, joint_state_deadline_ms, stopped_velocity: after a
  // software stop the arm must be still (every |velocity| below
  // stopped_velocity) within stop_deadline, else power cut. A joint state
  // older than joint_state_deadline cannot show that. Microseconds.
  int64_t stop_deadline_us = 0;
  int64_t joint_state_deadline_us = 0;
  double stopped_velocity = 0;  // rad/s (or m/s)
  // power_cut: "lcm" (power_relay_t on channels.power), "usb_hid_relay" or
  // "serial_pulse".
  std::string power_cut;
  // usb_hid_relay.{channel, serial}: USB HID relay board (16c0:05df): which
  // relay (1-based) switches the arm's power, wired normally open; serial ""
  // takes the only board.
  int relay_channel = 1;
  std::string relay_serial;
  // serial_pulse.{device, line, frequency_hz}: the dynamic power output
  // (serial_pulse_output.hpp, docs/intervene.md): a square wave of
  // frequency_hz (1..1000) on line "dtr", "rts" or "tx" of the serial
  // device, for a retriggerable watchdog that drops the arm's power when
  // the pulses stop.
  SerialPulseSettings serial_pulse;
};

// Reads (and finishes) the `intervention` section.
InterveneSettings read_intervene_settings(YamlMap section);

// Everything tofguard-intervene needs.
struct InterveneProcessSettings {
  LcmSettings lcm;
  ChannelNames channels;
  // With a key: risk verdicts and resets are taken only from the
  // authenticated channels, and the status and power commands are signed.
  auth::AuthSettings auth;
  InterveneSettings intervene;
};

// Everything tofguard-reset needs (it runs with or without a config).
struct ResetToolSettings {
  LcmSettings lcm;
  ChannelNames channels;
  // With a key the request goes out signed on channels.reset_auth; without
  // a config (no key file) it goes out plain, which only an insecure
  // tofguard-intervene accepts.
  auth::AuthSettings auth;
};

}  // namespace tofguard::settings

// The component's own names for its settings (tofguard::intervene::PulseLine, ...).
namespace tofguard::intervene {
using settings::InterveneProcessSettings;
using settings::InterveneSettings;
using settings::PulseLine;
using settings::read_intervene_settings;
using settings::ResetToolSettings;
using settings::SerialPulseSettings;
}  // namespace tofguard::intervene
