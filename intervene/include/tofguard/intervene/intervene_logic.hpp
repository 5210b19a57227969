#pragma once
// The permission to move: a latched, fail-safe state machine (no LCM, no
// clocks of its own: every call gets the time).
//
// Two clocks, as everywhere in tofguard: `now_us` is the monotonic clock
// (deadlines), `now_utime` the wall clock (only written into since_utime).
//
// Rules
// - It starts stopped (software stop, latched): motion is allowed only after
//   an accepted reset.
// - A DANGEROUS risk -> software stop, latched. The first cause stays the
//   stop's cause until a reset.
// - No SAFETY_RISK for risk_deadline_ms -> power cut (the risk stream itself
//   is dead), latched.
// - Once a software stop is older than stop_deadline_ms, the arm must be
//   still: a fresh joint state with every |velocity| <= stopped_velocity.
//   Otherwise (moving, or no fresh joint state to show it) -> power cut.
// - A power-cut actuator error -> stopped (it cannot cut the power any more),
//   reported, and no reset is accepted until the actuator works again.
// - A reset is accepted only while the current risk is SAFE and fresh, the
//   actuator works and who/why are given; it clears the latch.
// - No tick() (it runs at the publish rate) for longer than
//   risk_deadline_ms -> this process was held up: power cut, latched, and
//   no risk counts as fresh until one arrives risk_deadline_ms later (what
//   was queued meanwhile arrives "now" but is old).
#include <cstdint>
#include <string>

#include "tofguard/joint_state_t.hpp"
#include "tofguard/reset_request_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/settings/intervene_settings.hpp"

namespace tofguard::intervene {

// What safety_status_t carries (less utime and seq), plus the power.
struct Status {
  bool motion_allowed = false;
  int8_t stop = 0;  // safety_status_t::STOP_*
  bool latched = false;
  int8_t cause = 0;  // risk_t::CAUSE_*
  std::string reason;
  int64_t since_utime = 0;
  // False once a power cut is ordered.
  bool power_enabled = true;
};

struct ResetDecision {
  bool accepted = false;
  std::string reason;
};

class InterveneLogic {
 public:
  InterveneLogic(const InterveneSettings& config, int64_t now_us, int64_t now_utime);

  void on_risk(const risk_t& risk, int64_t now_us, int64_t now_utime);
  void on_joint_state(const joint_state_t& joints, int64_t now_us);
  ResetDecision on_reset(const reset_request_t& request, int64_t now_us, int64_t now_utime);
  // The power-cut actuator failed ("" = it works again).
  void on_actuator_result(const std::string& error, int64_t now_us, int64_t now_utime);
  // Applies the deadlines; call at least at the publish rate.
  void tick(int64_t now_us, int64_t now_utime);

  const Status& status() const { return status_; }
  // True once after every change of status(): publish at once.
  bool take_changed();

 private:
  void stop(int8_t kind, int8_t cause, const std::string& reason, int64_t now_us, int64_t now_utime);
  bool risk_fresh(int64_t now_us) const;
  // Stops (power cut) when no tick() came for longer than the risk
  // deadline (watched from the first tick on).
  void check_not_held_up(int64_t now_us, int64_t now_utime, bool from_tick);

  InterveneSettings config_;
  Status status_;
  bool changed_ = true;
  int64_t stop_started_us_ = 0;
  // Latest risk and when it arrived (monotonic); -1 = never.
  risk_t risk_;
  bool received_risk_ = false;
  int64_t risk_arrival_us_;
  // Latest joint state's largest |velocity| and which joint; -1 = never.
  double max_speed_ = 0;
  std::string fastest_joint_;
  int64_t joint_state_arrival_us_ = -1;
  std::string actuator_error_;
  // The last tick's time (monotonic), whether a tick came yet, and from
  // when a risk's arrival may count as fresh again after this process was
  // held up.
  int64_t last_tick_us_ = 0;
  bool watching_ = false;
  int64_t trusted_from_us_ = 0;
};

}  // namespace tofguard::intervene
