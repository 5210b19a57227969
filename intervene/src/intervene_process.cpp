#include "tofguard/intervene/intervene_process.hpp"

#include <iostream>
#include <memory>

#include "tofguard/common/clock.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/intervene/intervention_logic.hpp"
#include "tofguard/intervene/power_actuator.hpp"
#include "tofguard/intervene/serial_pulse_output.hpp"
#include "tofguard/power_relay_t.hpp"
#include "tofguard/reset_reply_t.hpp"
#include "tofguard/safety_status_t.hpp"

namespace tofguard::intervene {
namespace {

// The `lcm` actuator: power_relay_t on SAFETY_POWER.
class LcmPowerActuator : public PowerActuator {
 public:
  LcmPowerActuator(lcm::LCM& lcm, std::string channel) : lcm_(lcm), channel_(std::move(channel)) {}
  std::string set_power(bool enabled, const std::string& reason) override {
    power_relay_t message;
    message.utime = wall_utime();
    message.seq = seq_++;
    message.power_enabled = enabled;
    message.reason = reason;
    if (lcm_.publish(channel_, &message) != 0) return "cannot publish " + channel_;
    return "";
  }

 private:
  lcm::LCM& lcm_;
  std::string channel_;
  int64_t seq_ = 0;
};

}  // namespace

ProcessInfo process_info() {
  return {"tofguard-intervene",
          "Publishes the permission to move (SAFETY_STATUS, positive logic) at a fixed rate and\n"
          "at once on every change: starts stopped, stops on a DANGEROUS risk, cuts the power\n"
          "when the arm does not stop in time or the risk stream goes stale, and holds every\n"
          "stop until an accepted SAFETY_RESET (see tofguard-reset)."};
}

int run_intervene(const InterveneProcessSettings& settings) {
  LcmNode node(settings.lcm, settings.channels, "tofguard-intervene");
  InterventionLogic logic(settings.intervention, monotonic_us(), wall_utime());
  std::unique_ptr<PowerActuator> actuator;
  SerialPulseOutput* pulse_output = nullptr;  // the actuator, when it pulses
  if (settings.intervention.power_cut == "usb_hid_relay") {
    actuator = std::make_unique<UsbHidRelay>(settings.intervention.relay_channel,
                                             settings.intervention.relay_serial);
  } else if (settings.intervention.power_cut == "serial_pulse") {
    auto output = std::make_unique<SerialPulseOutput>(settings.intervention.serial_pulse);
    pulse_output = output.get();
    actuator = std::move(output);
  } else {
    actuator = std::make_unique<LcmPowerActuator>(node.safety(), settings.channels.power);
  }

  int64_t seq = 0;
  auto publish_status = [&] {
    const Status& s = logic.status();
    safety_status_t message;
    message.utime = wall_utime();
    message.seq = seq++;
    message.motion_allowed = s.motion_allowed;
    message.stop = s.stop;
    message.latched = s.latched;
    message.cause = s.cause;
    message.reason = s.reason;
    message.since_utime = s.since_utime;
    node.safety().publish(settings.channels.status, &message);
    node.counters().frames_out++;
    node.heartbeat().set_status(s.motion_allowed ? "motion allowed" : "stopped: " + s.reason);
  };
  auto apply_power = [&] {
    const std::string error = actuator->set_power(logic.status().power_enabled, logic.status().reason);
    if (!error.empty()) node.errors().report("actuator", error);
    logic.on_actuator_result(error, monotonic_us(), wall_utime());
  };
  // Publishes at once when something changed (and commands the power).
  auto publish_if_changed = [&] {
    if (logic.take_changed()) {
      apply_power();
      logic.take_changed();  // an actuator error is already in this status
      publish_status();
    }
  };

  node.subscribe<risk_t>(
      node.safety(), settings.channels.risk,
      [&](const risk_t& risk) {
        node.heartbeat().set_last_frame_utime(risk.utime);
        logic.on_risk(risk, monotonic_us(), wall_utime());
        publish_if_changed();
      },
      check_risk);
  node.subscribe<joint_state_t>(
      node.safety(), settings.channels.joint_state,
      [&](const joint_state_t& joints) { logic.on_joint_state(joints, monotonic_us()); }, check_joint_state);
  node.subscribe<reset_request_t>(
      node.safety(), settings.channels.reset, [&](const reset_request_t& request) {
        const ResetDecision decision = logic.on_reset(request, monotonic_us(), wall_utime());
        reset_reply_t reply;
        reply.utime = wall_utime();
        reply.request_id = request.request_id;
        reply.accepted = decision.accepted;
        reply.reason = decision.reason;
        std::cerr << "tofguard-intervene: reset from '" << request.who << "' (" << request.why
                  << "): " << decision.reason << std::endl;
        publish_if_changed();
        node.safety().publish(settings.channels.reset_reply, &reply);
      });
  node.add_timer(static_cast<int64_t>(1e6 / settings.intervention.publish_rate_hz), [&] {
    logic.tick(monotonic_us(), wall_utime());
    logic.take_changed();
    apply_power();  // re-asserted at the status rate: positive logic
    logic.take_changed();
    publish_status();
  });

  if (pulse_output != nullptr) {
    // The pulses come from this loop: if it hangs or the process dies, they
    // stop and the watchdog drops the power.
    node.add_timer(pulse_output->half_period_us(), [&] {
      const std::string error = pulse_output->half_period_tick();
      if (error.empty()) return;
      node.errors().report("actuator", error);
      logic.on_actuator_result(error, monotonic_us(), wall_utime());
      publish_if_changed();
    });
  }

  apply_power();
  logic.take_changed();
  publish_status();
  node.run();

  // Leaving: the last word is "stopped", for controllers that act on it
  // before their deadline runs out.
  logic.on_actuator_result("tofguard-intervene exiting", monotonic_us(), wall_utime());
  safety_status_t last;
  last.utime = wall_utime();
  last.seq = seq++;
  last.motion_allowed = false;
  last.stop = safety_status_t::STOP_SOFTWARE;
  last.latched = true;
  last.cause = risk_t::CAUSE_COMPONENT_FAULT;
  last.reason = "tofguard-intervene exiting";
  last.since_utime = last.utime;
  node.safety().publish(settings.channels.status, &last);
  actuator->set_power(false, "tofguard-intervene exiting");
  return 0;
}

}  // namespace tofguard::intervene
