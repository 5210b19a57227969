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
#include "tofguard/intervene/auth_refusals.hpp"
#include "tofguard/intervene/intervene_logic.hpp"
#include "tofguard/intervene/lcm_power_actuator.hpp"
#include "tofguard/intervene/power_actuator.hpp"
#include "tofguard/intervene/serial_pulse_output.hpp"
#include "tofguard/reset_reply_t.hpp"
#include "tofguard/safety_status_t.hpp"

namespace tofguard::intervene {
namespace {

// With a key, only signed risk verdicts and resets count, and the status
// and power commands go out signed as well as plain.
std::optional<auth::MessageVerifier> verifier_for(const auth::AuthSettings& auth) {
  if (!auth::authenticated(auth)) return std::nullopt;
  return std::optional<auth::MessageVerifier>(std::in_place, auth.key, auth.max_age_us);
}
std::optional<auth::MessageSigner> signer_for(const auth::AuthSettings& auth) {
  if (!auth::authenticated(auth)) return std::nullopt;
  return std::optional<auth::MessageSigner>(std::in_place, auth.key, wall_utime());
}

// The process: the intervene logic (InterveneLogic) between its inputs (risk verdicts,
// joint states, resets, the timers) and its outputs (the status, the power
// commands).
class Intervener {
 public:
  explicit Intervener(const InterveneProcessSettings& settings)
      : settings_(settings),
        channels_(settings.channels),
        node_(settings.lcm, settings.channels, "tofguard-intervene"),
        verifier_(verifier_for(settings.auth)),
        signer_(signer_for(settings.auth)),
        logic_(settings.intervene, monotonic_us(), wall_utime()) {
    make_actuator();
  }

  int run() {
    subscribe_risk();
    node_.subscribe<joint_state_t>(
        node_.safety(), channels_.joint_state,
        [&](const joint_state_t& joints) { logic_.on_joint_state(joints, monotonic_us()); },
        check_joint_state);
    subscribe_reset();
    add_timers();
    apply_power();
    logic_.take_changed();
    publish_status();
    node_.run();
    leave();
    return 0;
  }

 private:
  auth::MessageSigner* signer() { return signer_ ? &*signer_ : nullptr; }

  void make_actuator() {
    const InterveneSettings& section = settings_.intervene;
    if (section.power_cut == "usb_hid_relay") {
      actuator_ = std::make_unique<UsbHidRelay>(section.relay_channel, section.relay_serial);
    } else if (section.power_cut == "serial_pulse") {
      auto output = std::make_unique<SerialPulseOutput>(section.serial_pulse);
      pulse_output_ = output.get();
      actuator_ = std::move(output);
    } else {
      actuator_ =
          std::make_unique<LcmPowerActuator>(node_.safety(), channels_.power, channels_.power_auth, signer());
    }
  }

  void publish_status() {
    const Status& s = logic_.status();
    safety_status_t message;
    message.utime = wall_utime();
    message.seq = seq_++;
    message.motion_allowed = s.motion_allowed;
    message.stop = s.stop;
    message.latched = s.latched;
    message.cause = s.cause;
    message.reason = s.reason;
    message.since_utime = s.since_utime;
    auth::publish_signed(node_.safety(), signer(), channels_.status, channels_.status_auth, message,
                         wall_utime());
    node_.counters().frames_out++;
    node_.heartbeat().set_status((s.motion_allowed ? "motion allowed" : "stopped: " + s.reason) +
                                 refused_.summary());
  }

  void apply_power() {
    const std::string error = actuator_->set_power(logic_.status().power_enabled, logic_.status().reason);
    if (!error.empty()) node_.errors().report("actuator", error);
    logic_.on_actuator_result(error, monotonic_us(), wall_utime());
  }

  // Publishes at once when something changed (and commands the power).
  void publish_if_changed() {
    if (logic_.take_changed()) {
      apply_power();
      logic_.take_changed();  // an actuator error is already in this status
      publish_status();
    }
  }

  void on_risk(const risk_t& risk) {
    node_.heartbeat().set_last_frame_utime(risk.utime);
    logic_.on_risk(risk, monotonic_us(), wall_utime());
    publish_if_changed();
  }

  void subscribe_risk() {
    if (!verifier_) {
      node_.subscribe<risk_t>(
          node_.safety(), channels_.risk, [&](const risk_t& risk) { on_risk(risk); }, check_risk);
      return;
    }
    // The plain SAFETY_RISK is not read at all: only a verdict with a valid
    // tag is a verdict (a forged SAFE would be a permission).
    node_.subscribe<authenticated_message_t>(
        node_.safety(), channels_.risk_auth, [&](const authenticated_message_t& m) {
          std::string why;
          const std::optional<risk_t> risk = verifier_->open<risk_t>(m, channels_.risk, wall_utime(), &why);
          if (risk && (why = check_risk(*risk)).empty()) {
            on_risk(*risk);
          } else {
            refused_.refuse(node_, channels_.risk_auth, why);
          }
        });
  }

  void reply_to_reset(int64_t request_id, const ResetDecision& decision) {
    reset_reply_t reply;
    reply.utime = wall_utime();
    reply.request_id = request_id;
    reply.accepted = decision.accepted;
    reply.reason = decision.reason;
    node_.safety().publish(channels_.reset_reply, &reply);
  }

  // tofguard-reset sends its request again until answered (a datagram can
  // be lost): a repeat of the last request id gets the same answer, not a
  // second decision.
  void on_reset(const reset_request_t& request) {
    if (last_reset_request_id_ != 0 && request.request_id == last_reset_request_id_) {
      reply_to_reset(request.request_id, last_reset_decision_);
      return;
    }
    const ResetDecision decision = logic_.on_reset(request, monotonic_us(), wall_utime());
    last_reset_request_id_ = request.request_id;
    last_reset_decision_ = decision;
    std::cerr << "tofguard-intervene: reset from '" << request.who << "' (" << request.why
              << "): " << decision.reason << std::endl;
    publish_if_changed();
    reply_to_reset(request.request_id, decision);
  }

  void subscribe_reset() {
    if (!verifier_) {
      node_.subscribe<reset_request_t>(node_.safety(), channels_.reset,
                                       [&](const reset_request_t& request) { on_reset(request); });
      return;
    }
    // A plain reset is refused (and answered, so that whoever sent it
    // learns why); only a signed one reaches the logic.
    node_.subscribe<reset_request_t>(node_.safety(), channels_.reset, [&](const reset_request_t& request) {
      refused_.refuse(node_, channels_.reset,
                      "not authenticated (no tag): send it signed on " + channels_.reset_auth);
      reply_to_reset(request.request_id, {false,
                                          "refused: not authenticated: use tofguard-reset with the "
                                          "deployment's config (its auth.key_file)"});
    });
    node_.subscribe<authenticated_message_t>(
        node_.safety(), channels_.reset_auth, [&](const authenticated_message_t& m) {
          std::string why;
          const std::optional<reset_request_t> request =
              verifier_->open<reset_request_t>(m, channels_.reset, wall_utime(), &why);
          if (request) {
            on_reset(*request);
            return;
          }
          refused_.refuse(node_, channels_.reset_auth, why);
          // Answer the request id it claims (a refusal allows nothing).
          if (const auto claimed = decode_message<reset_request_t>(m.payload.data(), m.payload_size)) {
            reply_to_reset(claimed->request_id, {false, "refused: not authenticated: " + why});
          }
        });
  }

  void add_timers() {
    node_.add_timer(static_cast<int64_t>(1e6 / settings_.intervene.publish_rate_hz), [&] {
      logic_.tick(monotonic_us(), wall_utime());
      logic_.take_changed();
      apply_power();  // re-asserted at the status rate: positive logic
      logic_.take_changed();
      publish_status();
    });
    if (pulse_output_ == nullptr) return;
    // The pulses come from this loop: if it hangs or the process dies, they
    // stop and the watchdog drops the power.
    node_.add_timer(pulse_output_->half_period_us(), [&] {
      const std::string error = pulse_output_->half_period_tick();
      if (error.empty()) return;
      node_.errors().report("actuator", error);
      logic_.on_actuator_result(error, monotonic_us(), wall_utime());
      publish_if_changed();
    });
  }

  // Leaving: the last word is "stopped", for controllers that act on it
  // before their deadline runs out.
  void leave() {
    logic_.on_actuator_result("tofguard-intervene exiting", monotonic_us(), wall_utime());
    safety_status_t last;
    last.utime = wall_utime();
    last.seq = seq_++;
    last.motion_allowed = false;
    last.stop = safety_status_t::STOP_SOFTWARE;
    last.latched = true;
    last.cause = risk_t::CAUSE_COMPONENT_FAULT;
    last.reason = "tofguard-intervene exiting";
    last.since_utime = last.utime;
    auth::publish_signed(node_.safety(), signer(), channels_.status, channels_.status_auth, last,
                         wall_utime());
    actuator_->set_power(false, "tofguard-intervene exiting");
  }

  const InterveneProcessSettings& settings_;
  const ChannelNames& channels_;
  LcmNode node_;
  std::optional<auth::MessageVerifier> verifier_;
  std::optional<auth::MessageSigner> signer_;
  AuthRefusals refused_;
  InterveneLogic logic_;
  std::unique_ptr<PowerActuator> actuator_;
  SerialPulseOutput* pulse_output_ = nullptr;  // the actuator, when it pulses
  int64_t seq_ = 0;
  int64_t last_reset_request_id_ = 0;
  ResetDecision last_reset_decision_;
};

}  // namespace

ProcessInfo process_info() {
  return {"tofguard-intervene",
          "Publishes the permission to move (SAFETY_STATUS, positive logic) at a fixed rate and\n"
          "at once on every change: starts stopped, stops on a DANGEROUS risk, cuts the power\n"
          "when the arm does not stop in time or the risk stream goes stale, and holds every\n"
          "stop until an accepted SAFETY_RESET (see tofguard-reset)."};
}

int run_intervene(const InterveneProcessSettings& settings) { return Intervener(settings).run(); }

}  // namespace tofguard::intervene
