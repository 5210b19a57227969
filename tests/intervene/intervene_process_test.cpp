// tofguard-intervene as a real process over real LCM (private network
// namespace), driven through its wire contract and tofguard-reset. The
// embedded default has a key: the test signs what stands in for
// tofguard-risk as tofguard-risk would (signed_publisher.hpp).
#include <gtest/gtest.h>
#include <signal.h>
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <thread>

#include "pseudo_terminal.hpp"
#include "signed_publisher.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/power_relay_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

constexpr const char* kSafetyUrl = "udpm://239.255.76.67:7667?ttl=0";

struct Bench {
  lcm::LCM lcm{kSafetyUrl};
  SignedPublisher signed_lcm{lcm};
  std::vector<safety_status_t> statuses;
  power_relay_t last_power;
  int power_messages = 0;
  // What the fake risk classifier and arm keep sending while the test waits
  // (atomic: the reset feeder thread reads them too).
  bool send_risk = true;
  // False: the risk goes out plain only, as any process on the bus could
  // send it.
  bool sign_risk = true;
  std::atomic<int8_t> risk_level{risk_t::SAFE};
  std::atomic<int8_t> risk_cause{risk_t::CAUSE_NONE};
  int64_t last_feed_us = 0;

  Bench() {
    lcm.subscribe("SAFETY_STATUS", &Bench::on_status, this);
    lcm.subscribe("SAFETY_POWER", &Bench::on_power, this);
  }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const safety_status_t* s) {
    statuses.push_back(*s);
  }
  void on_power(const lcm::ReceiveBuffer*, const std::string&, const power_relay_t* p) {
    last_power = *p;
    ++power_messages;
  }
  // Feeds risk (every 20 ms) and a still arm, and handles what arrives.
  void pump() {
    const int64_t now = monotonic_us();
    if (now - last_feed_us >= 20000) {
      last_feed_us = now;
      if (send_risk) {
        risk_t r;
        r.utime = wall_utime();
        r.seq = 1;
        r.level = risk_level;
        r.cause = risk_cause;
        r.suspect = risk_cause == risk_t::CAUSE_JOINT_ERROR ? "a4" : "";
        r.score = 0;
        r.threshold = 0;
        r.detail = "from the test";
        if (sign_risk) {
          signed_lcm.publish("SAFETY_RISK", r);
        } else {
          lcm.publish("SAFETY_RISK", &r);
        }
      }
      joint_state_t j;
      j.utime = wall_utime();
      j.robot_id = "test";
      j.num_joints = 1;
      j.name = {"a1"};
      j.position = {0};
      j.velocity = {0};
      lcm.publish("JOINT_STATE", &j);
    }
    lcm.handleTimeout(5);
  }
  bool wait_for(const std::function<bool(const safety_status_t&)>& condition,
                std::chrono::milliseconds deadline) {
    statuses.clear();
    return wait_until(
        [&] {
          for (const auto& s : statuses) {
            if (condition(s)) return true;
          }
          return false;
        },
        deadline, [&] { pump(); });
  }
};

// Signed risks at the bench's level (and a still arm) every 20 ms from a
// thread of its own, while the test's thread waits for tofguard-reset.
class Feeder {
 public:
  explicit Feeder(Bench& bench) : bench_(bench), thread_([this] { run(); }) {}
  ~Feeder() {
    running_ = false;
    thread_.join();
  }
  // Risks sent with the DANGEROUS level: once one went out, none of the
  // SAFE ones before it can arrive after it (one socket, in order).
  int dangerous_sent() const { return dangerous_sent_; }

 private:
  void run() {
    lcm::LCM lcm(kSafetyUrl);
    SignedPublisher signed_lcm(lcm);
    while (running_) {
      risk_t r{};
      r.utime = wall_utime();
      r.seq = 1;
      r.level = bench_.risk_level;
      r.cause = bench_.risk_cause;
      signed_lcm.publish("SAFETY_RISK", r);
      if (r.level == risk_t::DANGEROUS) ++dangerous_sent_;
      joint_state_t j;
      j.utime = wall_utime();
      j.num_joints = 1;
      j.name = {"a1"};
      j.position = {0};
      j.velocity = {0};
      lcm.publish("JOINT_STATE", &j);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the feed's period
    }
  }
  Bench& bench_;
  std::atomic<bool> running_{true};
  std::atomic<int> dangerous_sent_{0};
  std::thread thread_;
};

std::vector<std::string> intervene_argv() {
  return {bin_dir() + "/tofguard-intervene", "--config", source_dir() + "/config/sim.yaml"};
}

// tofguard-reset with the deployment's config: signed with its key.
int reset(const std::string& name, std::string* out) {
  return run_command(name,
                     {bin_dir() + "/tofguard-reset", "--config", source_dir() + "/config/sim.yaml", "--who",
                      "test", "--why", "checked"},
                     out);
}

TEST(InterveneProcess, LatchedStopResetAndRestart) {
  ASSERT_TRUE(std::filesystem::exists(bin_dir() + "/tofguard-reset"));
  Bench bench;
  auto intervene = std::make_unique<Subprocess>("intervene-1", intervene_argv());

  // Comes up stopped and latched.
  ASSERT_TRUE(bench.wait_for([](const safety_status_t&) { return true; }, std::chrono::seconds(5)))
      << intervene->stderr_text();
  EXPECT_FALSE(bench.statuses.front().motion_allowed);
  EXPECT_TRUE(bench.statuses.front().latched);

  // A reset while the risk is SAFE is accepted; motion becomes allowed.
  ASSERT_TRUE(
      wait_until([&] { return bench.power_messages > 3; }, std::chrono::seconds(5), [&] { bench.pump(); }));
  std::string out;
  // tofguard-reset blocks; keep the feed going from a thread of its own.
  auto feeder = std::make_unique<Feeder>(bench);
  EXPECT_EQ(reset("reset-accepted", &out), 0) << out;
  EXPECT_NE(out.find("reset accepted"), std::string::npos) << out;
  ASSERT_TRUE(
      bench.wait_for([](const safety_status_t& s) { return s.motion_allowed; }, std::chrono::seconds(2)));

  // DANGEROUS -> motion withdrawn well within 200 ms of the risk.
  bench.risk_cause = risk_t::CAUSE_JOINT_ERROR;  // (the cause first: the feeder reads both)
  bench.risk_level = risk_t::DANGEROUS;
  bench.last_feed_us = 0;  // send it now
  const int64_t danger_sent_us = monotonic_us();
  ASSERT_TRUE(
      bench.wait_for([](const safety_status_t& s) { return !s.motion_allowed; }, std::chrono::seconds(2)));
  EXPECT_LT(monotonic_us() - danger_sent_us, 200000);
  const safety_status_t stopped = bench.statuses.back();
  EXPECT_EQ(stopped.cause, risk_t::CAUSE_JOINT_ERROR);
  EXPECT_EQ(stopped.stop, safety_status_t::STOP_SOFTWARE);
  EXPECT_TRUE(stopped.latched);

  // A reset while DANGEROUS is refused, with the reason. (Not before the
  // feeder thread's stream says DANGEROUS too: a SAFE it read just before
  // the change could otherwise be tofguard-intervene's newest risk.)
  ASSERT_TRUE(wait_until([&] { return feeder->dangerous_sent() > 0; }, std::chrono::seconds(2),
                         [&] { bench.pump(); }));
  EXPECT_EQ(reset("reset-refused", &out), 1) << out;
  EXPECT_NE(out.find("refused: diagnosis open: joint error"), std::string::npos) << out;
  feeder.reset();

  // The risk stream dies -> power cut.
  bench.send_risk = false;
  ASSERT_TRUE(
      bench.wait_for([](const safety_status_t& s) { return s.stop == safety_status_t::STOP_POWER_CUT; },
                     std::chrono::seconds(2)));
  EXPECT_FALSE(bench.last_power.power_enabled);
  EXPECT_EQ(bench.statuses.back().reason.rfind("SAFETY_RISK stale", 0), 0u) << bench.statuses.back().reason;
  EXPECT_EQ(bench.statuses.back().cause, risk_t::CAUSE_JOINT_ERROR);  // the first cause stays

  // Killed and restarted: comes up stopped.
  intervene->signal(SIGKILL);
  intervene->wait(std::chrono::seconds(5));
  intervene = std::make_unique<Subprocess>("intervene-2", intervene_argv());
  bench.send_risk = true;
  bench.risk_level = risk_t::SAFE;
  ASSERT_TRUE(bench.wait_for([](const safety_status_t&) { return true; }, std::chrono::seconds(5)));
  EXPECT_FALSE(bench.statuses.front().motion_allowed);
  EXPECT_TRUE(bench.statuses.front().latched);

  // SIGTERM: a last "stopped" status, exit code 0.
  intervene->signal(SIGTERM);
  EXPECT_EQ(intervene->wait(std::chrono::seconds(5)), 0);
}

// power_cut: serial_pulse on a pseudo-terminal (line tx). The output
// follows the power, not the permission to move (a software stop keeps the
// power so that the controller can brake): pulses while the risk stream is
// fresh, none while the process hangs (SIGSTOP), none after kill -9 and
// none once the stale stream cuts the power
// (the watchdog behind the output would drop it within its period).
TEST(InterveneProcess, ThePulsedPowerOutputStopsWhenThePowerIsCutOrTheProcessDies) {
  PseudoTerminal pty;
  ASSERT_FALSE(pty.device().empty()) << "no pseudo-terminal";
  const std::string config = sim_config_variant(
      "intervene_serial_pulse",
      {{"  power_cut: lcm\n", "  power_cut: serial_pulse\n  serial_pulse: {device: " + pty.device() +
                                  ", line: tx, frequency_hz: 25}\n"}});
  const std::vector<std::string> argv{bin_dir() + "/tofguard-intervene", "--config", config};
  Bench bench;
  std::string seen;
  const auto pulses_come = [&] {
    seen.clear();
    return wait_until([&] { return seen.size() >= 5; }, std::chrono::seconds(3),
                      [&] {
                        bench.pump();
                        seen += pty.available();
                      }) &&
           seen.find_first_not_of('\x55') == std::string::npos;
  };
  // No pulse for 300 ms (7 periods at 25 Hz) after what was in flight.
  const auto pulses_stopped = [&] {
    wait_until([] { return false; }, std::chrono::milliseconds(60), [&] { bench.pump(); });
    pty.available();
    seen.clear();
    wait_until([] { return false; }, std::chrono::milliseconds(300),
               [&] {
                 bench.pump();
                 seen += pty.available();
               });
    return seen.empty();
  };

  auto intervene = std::make_unique<Subprocess>("intervene-pulse-1", argv);
  ASSERT_TRUE(pulses_come()) << seen.size() << " pulses\n" << intervene->stderr_text();
  // A hang (SIGSTOP): the loop that makes the pulses stands still.
  intervene->signal(SIGSTOP);
  EXPECT_TRUE(pulses_stopped()) << seen.size() << " pulses while stopped by SIGSTOP";
  intervene->signal(SIGCONT);
  intervene->signal(SIGKILL);
  intervene->wait(std::chrono::seconds(5));
  EXPECT_TRUE(pulses_stopped()) << seen.size() << " pulses after kill -9";

  intervene = std::make_unique<Subprocess>("intervene-pulse-2", argv);
  ASSERT_TRUE(pulses_come()) << seen.size() << " pulses\n" << intervene->stderr_text();
  bench.send_risk = false;  // the risk stream dies: power cut
  ASSERT_TRUE(
      bench.wait_for([](const safety_status_t& s) { return s.stop == safety_status_t::STOP_POWER_CUT; },
                     std::chrono::seconds(2)));
  EXPECT_TRUE(pulses_stopped()) << seen.size() << " pulses after the power cut";
  intervene->signal(SIGTERM);
  EXPECT_EQ(intervene->wait(std::chrono::seconds(5)), 0);
}

}  // namespace
}  // namespace tofguard::test

namespace tofguard::test {
namespace {

struct HeartbeatOf {
  std::string process;
  heartbeat_t last;
  bool seen = false;
  void on(const lcm::ReceiveBuffer*, const std::string&, const heartbeat_t* hb) {
    if (hb->process == process) {
      last = *hb;
      seen = true;
    }
  }
};

TEST(InterveneProcess, MalformedInputIsDroppedCountedAndTheGoodRisksStillJudged) {
  Bench bench;
  HeartbeatOf heartbeat;
  heartbeat.process = "tofguard-intervene";
  bench.lcm.subscribe("SAFETY_HEARTBEAT", &HeartbeatOf::on, &heartbeat);
  Subprocess intervene("intervene-malformed", intervene_argv());
  ASSERT_TRUE(wait_until([&] { return heartbeat.seen; }, std::chrono::seconds(5), [&] { bench.pump(); }))
      << intervene.stderr_text();

  // Wrong fingerprint and truncated bytes on SAFETY_RISK_AUTH; a signed
  // risk whose level does not exist; a joint state with NaN; a reset that
  // is not one.
  joint_state_t wrong_type;
  wrong_type.num_joints = 0;
  bench.lcm.publish("SAFETY_RISK_AUTH", &wrong_type);
  const uint8_t truncated[5] = {1, 2, 3, 4, 5};
  bench.lcm.publish("SAFETY_RISK_AUTH", truncated, sizeof truncated);
  risk_t impossible{};
  impossible.utime = wall_utime();
  impossible.level = 9;
  bench.signed_lcm.publish("SAFETY_RISK", impossible);
  joint_state_t nan_joint;
  nan_joint.utime = wall_utime();
  nan_joint.num_joints = 1;
  nan_joint.name = {"a1"};
  nan_joint.position = {std::nan("")};
  nan_joint.velocity = {0};
  bench.lcm.publish("JOINT_STATE", &nan_joint);
  bench.lcm.publish("SAFETY_RESET", truncated, sizeof truncated);

  ASSERT_TRUE(
      wait_until([&] { return heartbeat.last.decode_errors >= 3 && heartbeat.last.validation_errors >= 2; },
                 std::chrono::seconds(5), [&] { bench.pump(); }))
      << "decode " << heartbeat.last.decode_errors << " validation " << heartbeat.last.validation_errors;
  EXPECT_EQ(heartbeat.last.decode_errors, 3);
  EXPECT_EQ(heartbeat.last.validation_errors, 2);
  EXPECT_TRUE(intervene.running());

  // The good SAFE risks keep coming (pump): a reset is accepted, and a
  // DANGEROUS one still stops the arm.
  std::string out;
  {
    Feeder feeder(bench);  // SAFE, the bench's level
    EXPECT_EQ(reset("reset-after-malformed", &out), 0) << out;
  }
  bench.risk_level = risk_t::DANGEROUS;
  bench.risk_cause = risk_t::CAUSE_UNKNOWN_OBJECT;
  EXPECT_TRUE(
      bench.wait_for([](const safety_status_t& s) { return !s.motion_allowed; }, std::chrono::seconds(2)));
}

}  // namespace
}  // namespace tofguard::test

namespace tofguard::test {
namespace {

// docs/security.md. With a key, tofguard-intervene acts only on signed risk
// verdicts and resets: a stream of plain SAFE verdicts (anyone on the bus
// can send one) is no risk stream at all, a plain reset is refused and
// answered, a replayed signed SAFE verdict is refused, and each refusal is
// counted in the heartbeat. The controller's example verifier accepts the
// signed status and refuses one forged with another key.
TEST(InterveneProcess, OnlySignedVerdictsAndResetsAllowMotion) {
  Bench bench;
  HeartbeatOf heartbeat;
  heartbeat.process = "tofguard-intervene";
  bench.lcm.subscribe("SAFETY_HEARTBEAT", &HeartbeatOf::on, &heartbeat);

  // 1. Plain SAFE verdicts only: taken for no verdict at all, so the risk
  // deadline cuts the power, and a signed reset is refused.
  bench.sign_risk = false;
  auto intervene = std::make_unique<Subprocess>("intervene-auth-1", intervene_argv());
  ASSERT_TRUE(
      bench.wait_for([](const safety_status_t& s) { return s.stop == safety_status_t::STOP_POWER_CUT; },
                     std::chrono::seconds(3)))
      << intervene->stderr_text();
  EXPECT_EQ(bench.statuses.back().reason.rfind("no SAFETY_RISK received for", 0), 0u)
      << bench.statuses.back().reason;
  std::string out;
  EXPECT_EQ(reset("auth-reset-plain-risk", &out), 1) << out;
  EXPECT_NE(out.find("refused: no SAFETY_RISK received yet"), std::string::npos) << out;
  intervene->signal(SIGKILL);
  intervene->wait(std::chrono::seconds(5));

  // 2. Signed verdicts: a plain reset (tofguard-reset without the config's
  // key) is refused with the reason, and counted.
  bench.sign_risk = true;
  heartbeat.seen = false;
  intervene = std::make_unique<Subprocess>("intervene-auth-2", intervene_argv());
  ASSERT_TRUE(wait_until([&] { return heartbeat.seen && bench.power_messages > 3; }, std::chrono::seconds(5),
                         [&] { bench.pump(); }));
  const int64_t refused_before = heartbeat.last.validation_errors;
  {
    Feeder feeder(bench);
    EXPECT_EQ(
        run_command("auth-reset-plain", {bin_dir() + "/tofguard-reset", "--who", "x", "--why", "y"}, &out), 1)
        << out;
    EXPECT_NE(out.find("refused: not authenticated"), std::string::npos) << out;
    // A signed reset is accepted.
    EXPECT_EQ(reset("auth-reset-signed", &out), 0) << out;
  }
  ASSERT_TRUE(
      bench.wait_for([](const safety_status_t& s) { return s.motion_allowed; }, std::chrono::seconds(2)));

  // 3. A signed SAFE verdict recorded now, replayed after a DANGEROUS stop:
  // refused as a replay, the stop stays.
  risk_t safe{};
  safe.utime = wall_utime();
  safe.level = risk_t::SAFE;
  const authenticated_message_t recorded = bench.signed_lcm.publish_signed_only("SAFETY_RISK", safe);
  bench.risk_level = risk_t::DANGEROUS;
  bench.risk_cause = risk_t::CAUSE_UNKNOWN_OBJECT;
  ASSERT_TRUE(
      bench.wait_for([](const safety_status_t& s) { return !s.motion_allowed; }, std::chrono::seconds(2)));
  bench.send_risk = false;
  for (int i = 0; i < 3; ++i) bench.lcm.publish("SAFETY_RISK_AUTH", &recorded);
  ASSERT_TRUE(wait_until([&] { return heartbeat.last.status.find("replayed: seq") != std::string::npos; },
                         std::chrono::seconds(2), [&] { bench.pump(); }))
      << heartbeat.last.status;
  EXPECT_GE(heartbeat.last.validation_errors, refused_before + 4);  // the plain reset, 3 replays
  EXPECT_NE(heartbeat.last.status.find("messages refused by authentication"), std::string::npos);
  EXPECT_FALSE(bench.statuses.empty() || bench.statuses.back().motion_allowed);

  // 4. The controller's side: the example verifier accepts the signed
  // statuses and refuses a "motion allowed" forged with another key.
  const std::string other_key = output_dir() + "/intervene-auth-other.key";
  std::filesystem::remove(other_key);
  ASSERT_EQ(run_command("auth-keygen-other", {bin_dir() + "/tofguard-keygen", other_key}), 0);
  SignedPublisher forger(bench.lcm, other_key);
  // The same stream recorded, for the Python example.
  const std::string log = output_dir() + "/intervene-auth-status.lcmlog";
  std::filesystem::remove(log);
  Subprocess logger("auth-lcm-logger", {"/usr/bin/lcm-logger", "-q", "-f", "-c", "SAFETY_STATUS_AUTH",
                                        std::string("--lcm-url=") + kSafetyUrl, log});
  ASSERT_TRUE(wait_until([&] { return std::filesystem::exists(log) && std::filesystem::file_size(log) > 0; },
                         std::chrono::seconds(5), [&] { bench.pump(); }))
      << logger.stderr_text();
  Subprocess controller("auth-controller", {bin_dir() + "/tofguard-verify-status-example", "--key",
                                            default_key_file(), "--count", "25", "--timeout-ms", "3000"});
  bench.send_risk = true;
  safety_status_t forged{};
  forged.utime = wall_utime();
  forged.motion_allowed = true;
  forged.reason = "forged";
  ASSERT_TRUE(wait_until([&] { return !controller.running(); }, std::chrono::seconds(5),
                         [&] {
                           bench.pump();
                           forger.publish_signed_only("SAFETY_STATUS", forged);
                         }));
  EXPECT_EQ(controller.wait(std::chrono::seconds(1)), 0) << controller.stderr_text();
  const std::string seen = controller.stdout_text();
  EXPECT_NE(seen.find("accepted seq="), std::string::npos) << seen;
  EXPECT_EQ(seen.find("motion_allowed=1"), std::string::npos) << seen;  // stopped, and the forgery refused
  EXPECT_NE(seen.find("refused: signed with key"), std::string::npos) << seen;

  // The Python example on the recorded stream gives the same verdicts.
  // (Stop the logger once 5 more statuses came here: it has them too.)
  const size_t statuses_now = bench.statuses.size();
  wait_until([&] { return bench.statuses.size() >= statuses_now + 5; }, std::chrono::seconds(2),
             [&] { bench.pump(); });
  logger.signal(SIGINT);
  ASSERT_EQ(logger.wait(std::chrono::seconds(5)), 0) << logger.stderr_text();
  std::string python_out, python_err;
  ASSERT_EQ(run_command("auth-python-example",
                        {"/usr/bin/python3", source_dir() + "/auth/examples/verify_status.py", "--key",
                         default_key_file(), log},
                        &python_out, &python_err),
            0)
      << python_err;
  size_t python_accepted = 0;
  for (size_t at = 0; (at = python_out.find("accepted seq=", at)) != std::string::npos; ++at)
    ++python_accepted;
  EXPECT_GE(python_accepted, 25u) << python_out;
  EXPECT_EQ(python_out.find("motion_allowed=1"), std::string::npos) << python_out;
  EXPECT_NE(python_out.find("refused: signed with key"), std::string::npos) << python_out;
  // Every status the C++ example accepted, the Python one accepted too.
  std::istringstream cpp_lines(seen);
  for (std::string line; std::getline(cpp_lines, line);) {
    if (line.rfind("accepted ", 0) == 0) {
      EXPECT_NE(python_out.find(line + "\n"), std::string::npos) << line;
    }
  }
  intervene->signal(SIGTERM);
  EXPECT_EQ(intervene->wait(std::chrono::seconds(5)), 0);
}

}  // namespace
}  // namespace tofguard::test
