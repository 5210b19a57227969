#include "tofguard/settings/intervene_settings.hpp"

namespace tofguard::settings {

InterveneSettings read_intervene_settings(YamlMap map) {
  InterveneSettings in;
  in.publish_rate_hz = map.number("publish_rate_hz", 10, 1000);
  in.risk_deadline_us = map.milliseconds_as_us("risk_deadline_ms", 1, 10000);
  in.stop_deadline_us = map.milliseconds_as_us("stop_deadline_ms", 1, 10000);
  in.joint_state_deadline_us = map.milliseconds_as_us("joint_state_deadline_ms", 1, 10000);
  in.stopped_velocity = map.number("stopped_velocity", 0, 10);
  in.power_cut = map.choice("power_cut", {"lcm", "usb_hid_relay", "serial_pulse"});
  if (auto relay = map.optional_map("usb_hid_relay")) {
    in.relay_channel = static_cast<int>(relay->integer("channel", 1, 8));
    in.relay_serial = relay->optional_string("serial").value_or("");
    relay->finish();
  } else if (in.power_cut == "usb_hid_relay") {
    map.fail("usb_hid_relay", "a mapping with channel (and serial) when power_cut is usb_hid_relay");
  }
  if (auto pulse = map.optional_map("serial_pulse")) {
    in.serial_pulse.device = pulse->string("device");
    const std::string line = pulse->choice("line", {"dtr", "rts", "tx"});
    in.serial_pulse.line =
        line == "tx" ? PulseLine::kTx : (line == "rts" ? PulseLine::kRts : PulseLine::kDtr);
    in.serial_pulse.frequency_hz = pulse->number("frequency_hz", 1, 1000);
    pulse->finish();
  } else if (in.power_cut == "serial_pulse") {
    map.fail("serial_pulse", "a mapping with device, line and frequency_hz when power_cut is serial_pulse");
  }
  map.finish();
  return in;
}

}  // namespace tofguard::settings
