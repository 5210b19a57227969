#include "tofguard/intervene/intervene_logic.hpp"

#include <cmath>
#include <sstream>

#include "tofguard/common/demand.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/safety_status_t.hpp"

namespace tofguard::intervene {
namespace {

std::string ms(int64_t us) {
  std::ostringstream s;
  s << us / 1000 << " ms";
  return s.str();
}

std::string describe(const risk_t& risk) {
  std::string text = risk_level_name(risk.level) + ": " + risk_cause_name(risk.cause);
  if (!risk.suspect.empty()) text += ", suspect " + risk.suspect;
  if (!risk.detail.empty()) text += " (" + risk.detail + ")";
  return text;
}

// The published status must never contradict itself: motion is allowed
// exactly when there is no stop and no latch, and the power is off only
// under a power cut. A robot controller reading motion_allowed alone must
// see the same decision as one reading stop or latched.
void demand_consistent(const Status& s) {
  TOFGUARD_DEMAND(s.motion_allowed == (s.stop == safety_status_t::STOP_NONE) &&
                      s.motion_allowed == !s.latched &&
                      (s.power_enabled || s.stop == safety_status_t::STOP_POWER_CUT),
                  "inconsistent status: motion_allowed " + std::to_string(s.motion_allowed) + ", stop " +
                      std::to_string(s.stop) + ", latched " + std::to_string(s.latched) + ", power_enabled " +
                      std::to_string(s.power_enabled));
}

}  // namespace

InterveneLogic::InterveneLogic(const InterveneSettings& config, int64_t now_us, int64_t now_utime)
    : config_(config), risk_arrival_us_(now_us) {
  // Fail-safe start: stopped and latched. The risk deadline runs from now,
  // so a chain that never starts ends in a power cut.
  status_.motion_allowed = false;
  status_.stop = safety_status_t::STOP_SOFTWARE;
  status_.latched = true;
  status_.cause = risk_t::CAUSE_NONE;
  status_.reason = "starting up: motion not allowed until a reset is accepted";
  status_.since_utime = now_utime;
  status_.power_enabled = true;
  stop_started_us_ = now_us;
  risk_.level = risk_t::DANGEROUS;  // no risk seen yet: never SAFE
  risk_.cause = risk_t::CAUSE_NONE;
  risk_.detail = "no SAFETY_RISK received yet";
  risk_arrival_us_ = now_us;
  risk_.utime = 0;
  risk_.seq = -1;
  received_risk_ = false;
}

bool InterveneLogic::take_changed() {
  const bool changed = changed_;
  changed_ = false;
  return changed;
}

bool InterveneLogic::risk_fresh(int64_t now_us) const {
  // Before the first risk, the deadline runs from start-up. After this
  // process was held up, only a risk that arrived a deadline later is
  // known not to have waited in the socket buffer meanwhile.
  return now_us - risk_arrival_us_ <= config_.risk_deadline_us && risk_arrival_us_ >= trusted_from_us_;
}

void InterveneLogic::check_not_held_up(int64_t now_us, int64_t now_utime, bool from_tick) {
  // The timer calls tick() at the publish rate: a longer silence than the
  // risk deadline means this process did not run (stopped, starved,
  // swapped). What it handles next was queued meanwhile and arrives "now"
  // on the monotonic clock: a SAFE verdict from before the hang would look
  // fresh. So: stopped and the power cut, and no risk is fresh until one
  // arrives a deadline after the hang was seen. (The first tick starts
  // the watch.)
  const int64_t silent_us = now_us - last_tick_us_;
  if (from_tick) last_tick_us_ = std::max(last_tick_us_, now_us);
  if (!watching_ || silent_us <= config_.risk_deadline_us) {
    watching_ = watching_ || from_tick;
    return;
  }
  if (!from_tick) last_tick_us_ = now_us;  // seen once, not again for every queued message
  trusted_from_us_ = now_us + config_.risk_deadline_us;
  stop(
      safety_status_t::STOP_POWER_CUT, risk_t::CAUSE_COMPONENT_FAULT,
      "tofguard-intervene did not run for " + ms(silent_us) +
          " (held up or starved, longer than the risk deadline): the inputs queued meanwhile are not trusted",
      now_us, now_utime);
}

void InterveneLogic::stop(int8_t kind, int8_t cause, const std::string& reason, int64_t now_us,
                          int64_t now_utime) {
  if (status_.motion_allowed) {
    status_.motion_allowed = false;
    status_.stop = kind;
    status_.latched = true;
    status_.cause = cause;
    status_.reason = reason;
    status_.since_utime = now_utime;
    status_.power_enabled = kind != safety_status_t::STOP_POWER_CUT;
    stop_started_us_ = now_us;
    changed_ = true;
    demand_consistent(status_);
    return;
  }
  // Already stopped: a stop only escalates (software -> power cut); the
  // first cause stays, the escalation's reason is added.
  if (kind > status_.stop) {
    status_.stop = kind;
    status_.power_enabled = false;
    if (status_.cause == risk_t::CAUSE_NONE) status_.cause = cause;
    status_.reason = reason + "; stopped before: " + status_.reason;
    changed_ = true;
  }
  demand_consistent(status_);
}

void InterveneLogic::on_risk(const risk_t& risk, int64_t now_us, int64_t now_utime) {
  check_not_held_up(now_us, now_utime, /*from_tick=*/false);
  risk_ = risk;
  risk_arrival_us_ = now_us;
  received_risk_ = true;
  if (risk.level == risk_t::DANGEROUS) {
    stop(safety_status_t::STOP_SOFTWARE, risk.cause, describe(risk), now_us, now_utime);
  }
}

void InterveneLogic::on_joint_state(const joint_state_t& joints, int64_t now_us) {
  max_speed_ = 0;
  fastest_joint_.clear();
  for (int i = 0; i < joints.num_joints; ++i) {
    const double speed = std::abs(joints.velocity[i]);
    if (speed >= max_speed_) {
      max_speed_ = speed;
      fastest_joint_ = joints.name[i];
    }
  }
  joint_state_arrival_us_ = now_us;
}

void InterveneLogic::on_actuator_result(const std::string& error, int64_t now_us, int64_t now_utime) {
  if (error == actuator_error_) return;
  actuator_error_ = error;
  if (!error.empty()) {
    stop(safety_status_t::STOP_SOFTWARE, risk_t::CAUSE_COMPONENT_FAULT, "power-cut actuator error: " + error,
         now_us, now_utime);
  }
  changed_ = true;
}

void InterveneLogic::tick(int64_t now_us, int64_t now_utime) {
  check_not_held_up(now_us, now_utime, /*from_tick=*/true);
  if (!risk_fresh(now_us)) {
    const std::string reason = received_risk_
                                   ? "SAFETY_RISK stale: none for " + ms(now_us - risk_arrival_us_)
                                   : "no SAFETY_RISK received for " + ms(now_us - risk_arrival_us_);
    stop(safety_status_t::STOP_POWER_CUT, risk_t::CAUSE_COMPONENT_FAULT, reason, now_us, now_utime);
  }
  if (status_.stop == safety_status_t::STOP_SOFTWARE &&
      now_us - stop_started_us_ > config_.stop_deadline_us) {
    const bool joint_state_fresh =
        joint_state_arrival_us_ >= 0 && now_us - joint_state_arrival_us_ <= config_.joint_state_deadline_us;
    if (!joint_state_fresh) {
      stop(safety_status_t::STOP_POWER_CUT, risk_t::CAUSE_SENSOR_FAULT,
           "no fresh JOINT_STATE shows the arm stopped " + ms(now_us - stop_started_us_) + " after the stop",
           now_us, now_utime);
    } else if (max_speed_ > config_.stopped_velocity) {
      std::ostringstream reason;
      reason << "arm still moving " << ms(now_us - stop_started_us_) << " after the stop (" << fastest_joint_
             << " at " << max_speed_ << ")";
      stop(safety_status_t::STOP_POWER_CUT, status_.cause, reason.str(), now_us, now_utime);
    }
  }
}

ResetDecision InterveneLogic::on_reset(const reset_request_t& request, int64_t now_us, int64_t now_utime) {
  check_not_held_up(now_us, now_utime, /*from_tick=*/false);
  if (request.who.empty() || request.why.empty()) {
    return {false, "refused: a reset needs who and why"};
  }
  if (!status_.latched) return {false, "refused: nothing to reset, motion is allowed"};
  if (!actuator_error_.empty()) {
    return {false, "refused: power-cut actuator error: " + actuator_error_};
  }
  if (!received_risk_) return {false, "refused: no SAFETY_RISK received yet"};
  if (!risk_fresh(now_us)) {
    return {false, "refused: SAFETY_RISK stale for " + ms(now_us - risk_arrival_us_)};
  }
  // A DANGEROUS frame verdict is an open diagnosis: tofguard-risk keeps it
  // (cause and suspect as at the stop) until the fault has been gone for
  // risk.evidence.clear_frames frames, so no single SAFE verdict comes while
  // it persists. A timeout verdict (seq -1) is not a diagnosis.
  if (risk_.level == risk_t::DANGEROUS && risk_.seq >= 0) {
    std::string text = "refused: diagnosis open: " + risk_cause_name(risk_.cause);
    if (!risk_.suspect.empty()) text += ", suspect " + risk_.suspect;
    if (!risk_.detail.empty()) text += " (" + risk_.detail + ")";
    return {false, text};
  }
  if (risk_.level != risk_t::SAFE) {
    return {false, "refused: current risk is " + describe(risk_)};
  }
  status_.motion_allowed = true;
  status_.stop = safety_status_t::STOP_NONE;
  status_.latched = false;
  status_.cause = risk_t::CAUSE_NONE;
  status_.reason = "reset accepted from " + request.who + ": " + request.why;
  status_.since_utime = now_utime;
  status_.power_enabled = true;
  changed_ = true;
  demand_consistent(status_);
  return {true, "accepted"};
}

}  // namespace tofguard::intervene
