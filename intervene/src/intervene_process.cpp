#include "tofguard/intervene/intervene_process.hpp"

#include <iostream>
#include <memory>
#include <optional>

#include "tofguard/auth/message_signer.hpp"
#include "tofguard/auth/message_verifier.hpp"
#include "tofguard/auth/signed_publish.hpp"
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

// The `lcm` actuator: power_relay_t on SAFETY_POWER, and with a key signed
// on SAFETY_POWER_AUTH first (power_enabled = true is a permission too).
class LcmPowerActuator : public PowerActuator {
 public:
  LcmPowerActuator(lcm::LCM& lcm, std::string channel, std::string auth_channel, auth::MessageSigner* signer)
      : lcm_(lcm), channel_(std::move(channel)), auth_channel_(std::move(auth_channel)), signer_(signer) {}
  std::string set_power(bool enabled, const std::string& reason) override {
    power_relay_t message;
    message.utime = wall_utime();
    message.seq = seq_++;
    message.power_enabled = enabled;
    message.reason = reason;
    return auth::publish_signed(lcm_, signer_, channel_, auth_channel_, message, wall_utime());
  }

 private:
  lcm::LCM& lcm_;
  std::string channel_;
  std::string auth_channel_;
  auth::MessageSigner* signer_;  // null: insecure
  int64_t seq_ = 0;
};

// Messages refused by the authentication: counted as validation errors in
// the heartbeat, reported in one line each (rate-limited per channel), and
// summed up in the heartbeat's status.
struct AuthRefusals {
  int64_t count = 0;
  std::string last;

  void refuse(LcmNode& node, const std::string& channel, const std::string& why) {
    ++count;
    last = channel + ": " + why;
    node.counters().validation_errors++;
    node.errors().report(channel, channel + ": refused: " + why);
  }
  std::string summary() const {
    if (count == 0) return "";
    return "; " + std::to_string(count) + " messages refused by authentication (last: " + last + ")";
  }
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
  const ChannelNames& channels = settings.channels;
  // With a key, only signed risk verdicts and resets count, and the status
  // and power commands go out signed as well as plain.
  std::optional<auth::MessageVerifier> verifier;
  std::optional<auth::MessageSigner> signer;
  if (auth::authenticated(settings.auth)) {
    verifier.emplace(settings.auth.key, settings.auth.max_age_us);
    signer.emplace(settings.auth.key, wall_utime());
  }
  auth::MessageSigner* const signer_or_null = signer ? &*signer : nullptr;
  AuthRefusals refused;
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
    actuator = std::make_unique<LcmPowerActuator>(node.safety(), channels.power, channels.power_auth,
                                                  signer_or_null);
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
    auth::publish_signed(node.safety(), signer_or_null, channels.status, channels.status_auth, message,
                         wall_utime());
    node.counters().frames_out++;
    node.heartbeat().set_status((s.motion_allowed ? "motion allowed" : "stopped: " + s.reason) +
                                refused.summary());
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

  auto on_risk = [&](const risk_t& risk) {
    node.heartbeat().set_last_frame_utime(risk.utime);
    logic.on_risk(risk, monotonic_us(), wall_utime());
    publish_if_changed();
  };
  if (verifier) {
    // The plain SAFETY_RISK is not read at all: only a verdict with a valid
    // tag is a verdict (a forged SAFE would be a permission).
    node.subscribe<authenticated_message_t>(
        node.safety(), channels.risk_auth, [&](const authenticated_message_t& m) {
          std::string why;
          const std::optional<risk_t> risk = verifier->open<risk_t>(m, channels.risk, wall_utime(), &why);
          if (risk && (why = check_risk(*risk)).empty()) {
            on_risk(*risk);
          } else {
            refused.refuse(node, channels.risk_auth, why);
          }
        });
  } else {
    node.subscribe<risk_t>(node.safety(), channels.risk, on_risk, check_risk);
  }
  node.subscribe<joint_state_t>(
      node.safety(), settings.channels.joint_state,
      [&](const joint_state_t& joints) { logic.on_joint_state(joints, monotonic_us()); }, check_joint_state);
  auto reply_to_reset = [&](int64_t request_id, const ResetDecision& decision) {
    reset_reply_t reply;
    reply.utime = wall_utime();
    reply.request_id = request_id;
    reply.accepted = decision.accepted;
    reply.reason = decision.reason;
    node.safety().publish(channels.reset_reply, &reply);
  };
  // tofguard-reset sends its request again until answered (a datagram can
  // be lost): a repeat of the last request id gets the same answer, not a
  // second decision.
  int64_t last_reset_request_id = 0;
  ResetDecision last_reset_decision;
  auto on_reset = [&](const reset_request_t& request) {
    if (last_reset_request_id != 0 && request.request_id == last_reset_request_id) {
      reply_to_reset(request.request_id, last_reset_decision);
      return;
    }
    const ResetDecision decision = logic.on_reset(request, monotonic_us(), wall_utime());
    last_reset_request_id = request.request_id;
    last_reset_decision = decision;
    std::cerr << "tofguard-intervene: reset from '" << request.who << "' (" << request.why
              << "): " << decision.reason << std::endl;
    publish_if_changed();
    reply_to_reset(request.request_id, decision);
  };
  if (verifier) {
    // A plain reset is refused (and answered, so that whoever sent it
    // learns why); only a signed one reaches the logic.
    node.subscribe<reset_request_t>(node.safety(), channels.reset, [&](const reset_request_t& request) {
      refused.refuse(node, channels.reset,
                     "not authenticated (no tag): send it signed on " + channels.reset_auth);
      reply_to_reset(request.request_id, {false,
                                          "refused: not authenticated: use tofguard-reset with the "
                                          "deployment's config (its auth.key_file)"});
    });
    node.subscribe<authenticated_message_t>(
        node.safety(), channels.reset_auth, [&](const authenticated_message_t& m) {
          std::string why;
          const std::optional<reset_request_t> request =
              verifier->open<reset_request_t>(m, channels.reset, wall_utime(), &why);
          if (request) {
            on_reset(*request);
            return;
          }
          refused.refuse(node, channels.reset_auth, why);
          // Answer the request id it claims (a refusal allows nothing).
          if (const auto claimed = decode_message<reset_request_t>(m.payload.data(), m.payload_size)) {
            reply_to_reset(claimed->request_id, {false, "refused: not authenticated: " + why});
          }
        });
  } else {
    node.subscribe<reset_request_t>(node.safety(), channels.reset, on_reset);
  }
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
  auth::publish_signed(node.safety(), signer_or_null, channels.status, channels.status_auth, last,
                       wall_utime());
  actuator->set_power(false, "tofguard-intervene exiting");
  return 0;
}

}  // namespace tofguard::intervene
