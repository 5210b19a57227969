// The permission to move as a pure state machine: times are given in
// microseconds of the monotonic clock, so every deadline is exact.
#include <gtest/gtest.h>

#include "tofguard/intervene/intervene_logic.hpp"
#include "tofguard/intervene/power_actuator.hpp"
#include "tofguard/safety_status_t.hpp"

namespace tofguard::intervene {
namespace {

constexpr int64_t kMs = 1000;
constexpr int64_t kUtime0 = 1700000000000000;

InterveneSettings test_config() {
  InterveneSettings c;
  c.publish_rate_hz = 50;
  c.risk_deadline_us = 200000;
  c.stop_deadline_us = 300000;
  c.joint_state_deadline_us = 100000;
  c.stopped_velocity = 0.02;
  c.power_cut = "lcm";
  return c;
}

risk_t risk(int8_t level, int8_t cause = risk_t::CAUSE_NONE, const std::string& suspect = "") {
  risk_t r;
  r.utime = kUtime0;
  r.seq = 1;
  r.level = level;
  r.cause = cause;
  r.suspect = suspect;
  r.score = 0;
  r.threshold = 0;
  r.detail = "test";
  return r;
}

joint_state_t joints(double a3_velocity) {
  joint_state_t j;
  j.utime = kUtime0;
  j.num_joints = 2;
  j.name = {"a2", "a3"};
  j.position = {0, 0};
  j.velocity = {0.0, a3_velocity};
  return j;
}

reset_request_t reset(const std::string& who = "nurse", const std::string& why = "checked the arm") {
  reset_request_t r;
  r.utime = kUtime0;
  r.request_id = 7;
  r.who = who;
  r.why = why;
  return r;
}

// Brought to "motion allowed" at t = 10 ms.
InterveneLogic running_logic() {
  InterveneLogic logic(test_config(), 0, kUtime0);
  logic.on_risk(risk(risk_t::SAFE), 5 * kMs, kUtime0);
  EXPECT_TRUE(logic.on_reset(reset(), 10 * kMs, kUtime0).accepted);
  return logic;
}

TEST(InterveneLogic, StartsStoppedAndLatched) {
  InterveneLogic logic(test_config(), 0, kUtime0);
  EXPECT_FALSE(logic.status().motion_allowed);
  EXPECT_TRUE(logic.status().latched);
  EXPECT_EQ(logic.status().stop, safety_status_t::STOP_SOFTWARE);
  EXPECT_NE(logic.status().reason.find("starting up"), std::string::npos);
  EXPECT_TRUE(logic.take_changed());
  EXPECT_FALSE(logic.take_changed());
}

TEST(InterveneLogic, ResetOnlyWhileTheCurrentRiskIsSafeAndFresh) {
  InterveneLogic logic(test_config(), 0, kUtime0);
  auto d = logic.on_reset(reset(), 1 * kMs, kUtime0);
  EXPECT_FALSE(d.accepted);
  EXPECT_EQ(d.reason, "refused: no SAFETY_RISK received yet");

  logic.on_risk(risk(risk_t::DANGEROUS, risk_t::CAUSE_UNKNOWN_OBJECT), 2 * kMs, kUtime0);
  d = logic.on_reset(reset(), 3 * kMs, kUtime0);
  EXPECT_FALSE(d.accepted);
  EXPECT_EQ(d.reason, "refused: diagnosis open: unknown object (test)");

  // The diagnosis names its suspect and the detail tofguard-risk gave.
  risk_t open = risk(risk_t::DANGEROUS, risk_t::CAUSE_JOINT_ERROR, "a4");
  open.seq = 120;
  open.detail =
      "diagnosis open since seq 101: joint a4 reads other than seen (sequential evidence, CUSUM "
      "log-likelihood "
      "ratio): 20.6 of h 20.6; this frame: no finding [clean 3/10 frames]";
  logic.on_risk(open, 3 * kMs, kUtime0);
  d = logic.on_reset(reset(), 3 * kMs, kUtime0);
  EXPECT_FALSE(d.accepted);
  EXPECT_EQ(d.reason, "refused: diagnosis open: joint error, suspect a4 (" + open.detail + ")");

  // A timeout (seq -1) is no diagnosis, but refused as well.
  risk_t timeout = risk(risk_t::DANGEROUS, risk_t::CAUSE_SENSOR_FAULT, "TOF_DEPTH");
  timeout.seq = -1;
  logic.on_risk(timeout, 3 * kMs, kUtime0);
  d = logic.on_reset(reset(), 3 * kMs, kUtime0);
  EXPECT_FALSE(d.accepted);
  EXPECT_NE(d.reason.find("refused: current risk is DANGEROUS: sensor fault, suspect TOF_DEPTH"),
            std::string::npos)
      << d.reason;

  logic.on_risk(risk(risk_t::WARNING), 4 * kMs, kUtime0);
  d = logic.on_reset(reset(), 5 * kMs, kUtime0);
  EXPECT_FALSE(d.accepted);
  EXPECT_NE(d.reason.find("refused: current risk is WARNING"), std::string::npos) << d.reason;

  logic.on_risk(risk(risk_t::SAFE), 6 * kMs, kUtime0);
  d = logic.on_reset(reset(), 7 * kMs, kUtime0 + 7000);
  EXPECT_TRUE(d.accepted) << d.reason;
  EXPECT_TRUE(logic.status().motion_allowed);
  EXPECT_FALSE(logic.status().latched);
  EXPECT_EQ(logic.status().stop, safety_status_t::STOP_NONE);
  EXPECT_EQ(logic.status().since_utime, kUtime0 + 7000);
  EXPECT_EQ(logic.status().reason, "reset accepted from nurse: checked the arm");

  // A SAFE risk that has gone stale no longer allows a reset.
  logic.on_risk(risk(risk_t::DANGEROUS, risk_t::CAUSE_JOINT_ERROR, "a4"), 8 * kMs, kUtime0);
  logic.on_risk(risk(risk_t::SAFE), 9 * kMs, kUtime0);
  d = logic.on_reset(reset(), 9 * kMs + 201 * kMs, kUtime0);
  EXPECT_FALSE(d.accepted);
  EXPECT_EQ(d.reason, "refused: SAFETY_RISK stale for 201 ms");
}

TEST(InterveneLogic, ResetNeedsWhoAndWhy) {
  InterveneLogic logic(test_config(), 0, kUtime0);
  logic.on_risk(risk(risk_t::SAFE), 1 * kMs, kUtime0);
  EXPECT_FALSE(logic.on_reset(reset("", "x"), 2 * kMs, kUtime0).accepted);
  EXPECT_FALSE(logic.on_reset(reset("x", ""), 2 * kMs, kUtime0).accepted);
}

TEST(InterveneLogic, DangerousStopsAndLatchesWithTheFirstCause) {
  InterveneLogic logic = running_logic();
  logic.take_changed();
  logic.on_risk(risk(risk_t::DANGEROUS, risk_t::CAUSE_JOINT_ERROR, "a4"), 20 * kMs, kUtime0 + 20000);
  EXPECT_TRUE(logic.take_changed());
  EXPECT_FALSE(logic.status().motion_allowed);
  EXPECT_TRUE(logic.status().latched);
  EXPECT_EQ(logic.status().stop, safety_status_t::STOP_SOFTWARE);
  EXPECT_EQ(logic.status().cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_NE(logic.status().reason.find("suspect a4"), std::string::npos) << logic.status().reason;
  EXPECT_EQ(logic.status().since_utime, kUtime0 + 20000);
  EXPECT_TRUE(logic.status().power_enabled);

  // SAFE frames do not release the latch; another danger keeps the first cause.
  logic.on_risk(risk(risk_t::SAFE), 30 * kMs, kUtime0);
  logic.on_risk(risk(risk_t::DANGEROUS, risk_t::CAUSE_UNKNOWN_OBJECT), 40 * kMs, kUtime0);
  EXPECT_FALSE(logic.status().motion_allowed);
  EXPECT_EQ(logic.status().cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_FALSE(logic.take_changed());
}

TEST(InterveneLogic, WarningKeepsMotionAllowed) {
  InterveneLogic logic = running_logic();
  logic.on_risk(risk(risk_t::WARNING, risk_t::CAUSE_UNKNOWN_OBJECT), 20 * kMs, kUtime0);
  logic.tick(30 * kMs, kUtime0);
  EXPECT_TRUE(logic.status().motion_allowed);
}

TEST(InterveneLogic, StaleRiskStreamCutsThePowerAtItsDeadline) {
  InterveneLogic logic = running_logic();
  logic.on_risk(risk(risk_t::SAFE), 100 * kMs, kUtime0);
  logic.tick(300 * kMs, kUtime0);  // exactly 200 ms: still fresh
  EXPECT_TRUE(logic.status().motion_allowed);
  logic.tick(301 * kMs, kUtime0);
  EXPECT_FALSE(logic.status().motion_allowed);
  EXPECT_EQ(logic.status().stop, safety_status_t::STOP_POWER_CUT);
  EXPECT_FALSE(logic.status().power_enabled);
  EXPECT_EQ(logic.status().cause, risk_t::CAUSE_COMPONENT_FAULT);
  EXPECT_EQ(logic.status().reason, "SAFETY_RISK stale: none for 201 ms");
}

TEST(InterveneLogic, HeldUpLongerThanTheRiskDeadlineStopsAndDistrustsWhatWasQueued) {
  InterveneLogic logic = running_logic();
  logic.tick(20 * kMs, kUtime0);
  logic.on_risk(risk(risk_t::SAFE), 30 * kMs, kUtime0);
  logic.tick(40 * kMs, kUtime0);
  EXPECT_TRUE(logic.status().motion_allowed);
  // Held up (SIGSTOP) for a second: the SAFE verdicts queued meanwhile
  // arrive at once, "fresh" on the monotonic clock.
  logic.on_risk(risk(risk_t::SAFE), 1040 * kMs, kUtime0);
  EXPECT_FALSE(logic.status().motion_allowed);
  EXPECT_EQ(logic.status().stop, safety_status_t::STOP_POWER_CUT);
  EXPECT_TRUE(logic.status().latched);
  EXPECT_EQ(logic.status().cause, risk_t::CAUSE_COMPONENT_FAULT);
  EXPECT_NE(logic.status().reason.find("tofguard-intervene did not run for 1000 ms"), std::string::npos)
      << logic.status().reason;
  logic.on_risk(risk(risk_t::SAFE), 1041 * kMs, kUtime0);
  logic.tick(1042 * kMs, kUtime0);
  // A queued reset is refused: no risk counts until one arrives a deadline
  // (200 ms) after the hang was seen.
  EXPECT_FALSE(logic.on_reset(reset(), 1043 * kMs, kUtime0).accepted);
  for (int64_t t = 1060; t <= 1220; t += 20) {
    logic.on_risk(risk(risk_t::SAFE), t * kMs, kUtime0);
    logic.tick(t * kMs + 1, kUtime0);
  }
  EXPECT_FALSE(logic.on_reset(reset(), 1225 * kMs, kUtime0).accepted);
  logic.on_risk(risk(risk_t::SAFE), 1245 * kMs, kUtime0);
  EXPECT_TRUE(logic.on_reset(reset(), 1246 * kMs, kUtime0).accepted);
  EXPECT_TRUE(logic.status().motion_allowed);
}

TEST(InterveneLogic, NoRiskEverCutsThePowerAfterStartUp) {
  InterveneLogic logic(test_config(), 0, kUtime0);
  logic.tick(200 * kMs, kUtime0);
  EXPECT_TRUE(logic.status().power_enabled);
  logic.tick(201 * kMs, kUtime0);
  EXPECT_FALSE(logic.status().power_enabled);
  EXPECT_EQ(logic.status().stop, safety_status_t::STOP_POWER_CUT);
}

TEST(InterveneLogic, ArmStillMovingAfterTheStopDeadlineCutsThePower) {
  InterveneLogic logic = running_logic();
  logic.on_risk(risk(risk_t::DANGEROUS, risk_t::CAUSE_UNKNOWN_OBJECT), 100 * kMs, kUtime0);
  // Keep the risk stream alive; the arm keeps moving at 0.5 rad/s on a3.
  for (int64_t t = 110; t <= 400; t += 10) {
    logic.on_risk(risk(risk_t::DANGEROUS, risk_t::CAUSE_UNKNOWN_OBJECT), t * kMs, kUtime0);
    logic.on_joint_state(joints(0.5), t * kMs);
    logic.tick(t * kMs, kUtime0);
    if (t <= 400) {
      EXPECT_EQ(logic.status().stop, safety_status_t::STOP_SOFTWARE) << "at " << t << " ms";
    }
  }
  logic.tick(401 * kMs, kUtime0);
  EXPECT_EQ(logic.status().stop, safety_status_t::STOP_POWER_CUT);
  EXPECT_FALSE(logic.status().power_enabled);
  EXPECT_EQ(logic.status().cause, risk_t::CAUSE_UNKNOWN_OBJECT);
  EXPECT_NE(logic.status().reason.find("arm still moving 301 ms after the stop (a3 at 0.5)"),
            std::string::npos)
      << logic.status().reason;
}

TEST(InterveneLogic, ArmThatStoppedKeepsThePower) {
  InterveneLogic logic = running_logic();
  logic.on_risk(risk(risk_t::DANGEROUS, risk_t::CAUSE_UNKNOWN_OBJECT), 100 * kMs, kUtime0);
  for (int64_t t = 110; t <= 1000; t += 10) {
    logic.on_risk(risk(risk_t::DANGEROUS, risk_t::CAUSE_UNKNOWN_OBJECT), t * kMs, kUtime0);
    logic.on_joint_state(joints(t < 300 ? 0.5 : 0.01), t * kMs);
    logic.tick(t * kMs, kUtime0);
  }
  EXPECT_EQ(logic.status().stop, safety_status_t::STOP_SOFTWARE);
  EXPECT_TRUE(logic.status().power_enabled);
}

TEST(InterveneLogic, NoJointStateToShowTheArmStoppedCutsThePower) {
  InterveneLogic logic = running_logic();
  logic.on_joint_state(joints(0.0), 50 * kMs);
  logic.on_risk(risk(risk_t::DANGEROUS, risk_t::CAUSE_UNKNOWN_OBJECT), 100 * kMs, kUtime0);
  for (int64_t t = 110; t <= 401; t += 10) {
    logic.on_risk(risk(risk_t::DANGEROUS, risk_t::CAUSE_UNKNOWN_OBJECT), t * kMs, kUtime0);
    logic.tick(t * kMs, kUtime0);
  }
  logic.tick(401 * kMs, kUtime0);
  EXPECT_EQ(logic.status().stop, safety_status_t::STOP_POWER_CUT);
  EXPECT_NE(logic.status().reason.find("no fresh JOINT_STATE"), std::string::npos) << logic.status().reason;
}

TEST(InterveneLogic, ActuatorErrorStopsAndBlocksResetUntilItWorks) {
  InterveneLogic logic = running_logic();
  logic.on_actuator_result("USB HID relay 16c0:05df not found", 20 * kMs, kUtime0);
  EXPECT_FALSE(logic.status().motion_allowed);
  EXPECT_EQ(logic.status().cause, risk_t::CAUSE_COMPONENT_FAULT);
  logic.on_risk(risk(risk_t::SAFE), 30 * kMs, kUtime0);
  auto d = logic.on_reset(reset(), 31 * kMs, kUtime0);
  EXPECT_FALSE(d.accepted);
  EXPECT_EQ(d.reason, "refused: power-cut actuator error: USB HID relay 16c0:05df not found");
  logic.on_actuator_result("", 40 * kMs, kUtime0);
  EXPECT_TRUE(logic.on_reset(reset(), 41 * kMs, kUtime0).accepted);
}

TEST(HidRelay, ReportsFollowTheBoardProtocol) {
  EXPECT_EQ(hid_relay_report(1, true), (std::array<uint8_t, 8>{0xFF, 1, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(hid_relay_report(2, false), (std::array<uint8_t, 8>{0xFD, 2, 0, 0, 0, 0, 0, 0}));
  const std::array<uint8_t, 8> state{'A', 'B', 'C', 'D', 'E', 0, 0, 0b00000010};
  EXPECT_FALSE(hid_relay_is_on(state, 1));
  EXPECT_TRUE(hid_relay_is_on(state, 2));
}

TEST(HidRelay, MissingBoardIsAnErrorNotAnException) {
  UsbHidRelay relay(1, "NOSUCH");
  const std::string error = relay.set_power(true, "test");
  EXPECT_FALSE(error.empty());
  EXPECT_NE(error.find("USB HID relay"), std::string::npos) << error;
}

}  // namespace
}  // namespace tofguard::intervene
