// tofguard-spy: the decoded lines of a log replayed into it with
// lcm-logplayer (private network namespace), its channel filter, and the
// status board's content.
#include <gtest/gtest.h>
#include <signal.h>
#include <lcm/lcm-cpp.hpp>

#include <cmath>
#include <filesystem>
#include <thread>

#include "sample_messages.hpp"
#include "tofguard/authenticated_message_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/speed_limit_t.hpp"
#include "tofguard/spy/message_format.hpp"
#include "tofguard/spy/status_board.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

const std::vector<std::pair<std::string, std::vector<uint8_t>>>& log_events() {
  static const std::vector<std::pair<std::string, std::vector<uint8_t>>> events = {
      {"TOF_DEPTH", encoded(sample_depth_image())},      {"JOINT_STATE", encoded(sample_joint_state())},
      {"SAFETY_RISK", encoded(sample_risk())},           {"SAFETY_STATUS", encoded(sample_safety_status())},
      {"SAFETY_HEARTBEAT", encoded(sample_heartbeat())}, {"JUNK", {1, 2, 3}},
  };
  return events;
}

const std::vector<std::string> kExpectedLines = {
    "TOF_DEPTH depth_image_t utime=1700000000123456 seq=42 camera=tof-test 4x3 valid=91.7% calibrated=true",
    "JOINT_STATE joint_state_t utime=1700000000200000 robot=friend-test a1=0.5000 a2=-1.2500 a3=3.0000",
    "SAFETY_RISK risk_t utime=1700000000123456 seq=42 DANGEROUS joint error suspect=a4 score=123.5 "
    "threshold=50 | "
    "joint a4 reads 10.0 deg less than seen",
    "SAFETY_STATUS safety_status_t seq=7 motion_allowed=false stop=software stop latched=true cause=joint "
    "error | "
    "DANGEROUS: joint error, suspect a4",
    "SAFETY_HEARTBEAT heartbeat_t tofguard-renderer pid=4242 seq=99 in=1000 out=998 dropped=2 "
    "decode_errors=3 "
    "validation_errors=4 | running",
    "JUNK ? fingerprint 0x0000000000000000 (3 bytes)",
};

std::string write_log(const std::string& name) {
  const std::string path = output_dir() + "/" + name + ".lcmlog";
  std::filesystem::remove(path);
  lcm::LogFile log(path, "w");
  int64_t t = 1700000000000000;
  // lcm-logplayer 1.3.1 may start reading before it has subscribed its
  // republisher and then drops the first events: a lead-in event 500 ms
  // ahead of the real ones takes that loss.
  static const uint8_t lead_in = 0;
  lcm::LogEvent first;
  first.eventnum = 0;
  first.timestamp = t - 500'000;
  first.channel = "LOG_LEAD_IN";
  first.datalen = 1;
  first.data = const_cast<uint8_t*>(&lead_in);
  log.writeEvent(&first);
  for (const auto& [channel, bytes] : log_events()) {
    lcm::LogEvent event;
    event.eventnum = 0;
    event.timestamp = t += 1000;
    event.channel = channel;
    event.datalen = static_cast<int32_t>(bytes.size());
    event.data = const_cast<uint8_t*>(bytes.data());
    log.writeEvent(&event);
  }
  return path;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream s(text);
  for (std::string line; std::getline(s, line);) {
    if (line.rfind("tofguard-spy:", 0) != 0 && line.rfind("SPY_PROBE", 0) != 0 &&
        line.rfind("LOG_LEAD_IN", 0) != 0)
      lines.push_back(line);
  }
  return lines;
}

// Replays `log` into a running `tofguard-spy --lines` with `extra` args;
// returns the decoded lines once `expected_count` have arrived.
std::vector<std::string> spy_on_replay(const std::string& name, const std::string& log,
                                       const std::vector<std::string>& extra, size_t expected_count) {
  std::vector<std::string> argv = {bin_dir() + "/tofguard-spy", "--lines"};
  // (SPY_PROBE lines are the readiness handshake, not part of the result.)
  argv.insert(argv.end(), extra.begin(), extra.end());
  Subprocess spy(name, argv);
  EXPECT_TRUE(wait_until([&] { return spy.stdout_text().find("listening on") != std::string::npos; },
                         std::chrono::seconds(5)));
  // The spy is surely receiving once it has printed a probe of ours.
  lcm::LCM probe_sender("udpm://239.255.76.67:7667?ttl=0");
  const uint8_t probe = 0;
  EXPECT_TRUE(wait_until(
      [&] {
        probe_sender.publish("SPY_PROBE", &probe, 1);
        return spy.stdout_text().find("SPY_PROBE") != std::string::npos;
      },
      std::chrono::seconds(5), [] { std::this_thread::sleep_for(std::chrono::milliseconds(20)); }));
  Subprocess player(name + "-player",
                    {"/usr/bin/lcm-logplayer", "--lcm-url=udpm://239.255.76.67:7667?ttl=0", "-s", "1", log});
  EXPECT_EQ(player.wait(std::chrono::seconds(10)), 0);
  EXPECT_TRUE(wait_until([&] { return lines_of(spy.stdout_text()).size() >= expected_count; },
                         std::chrono::seconds(5)))
      << spy.stdout_text();
  spy.signal(SIGINT);
  EXPECT_EQ(spy.wait(std::chrono::seconds(5)), 0);
  return lines_of(spy.stdout_text());
}

TEST(Spy, MotionEstimateLineShowsOffsetsInDegreesAndTheCameraCorrection) {
  motion_estimate_t m{};
  m.utime = 1700000000123456;
  m.seq = 42;
  m.camera_id = "tof-test";
  m.trigger = motion_estimate_t::TRIGGER_WARNING;
  m.usable = true;
  m.converged = true;
  m.iterations = 7;
  m.num_frames = 3;
  m.num_joints = 2;
  m.joint_name = {"a4", "a5"};
  m.reported_position = {1.0, 0.5};
  m.estimated_position = {1.0 - 10.0 * M_PI / 180, 0.5};
  m.position_sigma = {0.5 * M_PI / 180, 3.14};
  m.observable = {true, false};
  m.correction_translation[0] = 0.012;
  m.correction_translation[1] = -0.003;
  m.correction_translation[2] = 0;
  m.correction_rotation[0] = 1;
  m.correction_rotation[1] = m.correction_rotation[2] = m.correction_rotation[3] = 0;
  m.residual_before_mm = 30;
  m.residual_after_mm = 6;
  m.compute_us = 41500;
  const std::vector<uint8_t> bytes = encoded(m);
  EXPECT_EQ(
      spy::format_message("MOTION_ESTIMATE", bytes.data(), static_cast<int>(bytes.size())),
      "MOTION_ESTIMATE motion_estimate_t utime=1700000000123456 seq=42 trigger=1 usable=true converged=true "
      "iterations=7 frames=3 residual_mm=30.0->6.0 | a4=-10.0±0.5° | camera_mm=12.0,-3.0,0.0 camera_deg=0.0 "
      "compute_ms=41.5");
}

TEST(Spy, PrintsOneDecodedLinePerReplayedMessage) {
  const std::string log = write_log("spy-replay");
  EXPECT_EQ(spy_on_replay("spy-lines", log, {}, kExpectedLines.size()), kExpectedLines);
}

TEST(Spy, ChannelFilterKeepsOnlyMatchingChannels) {
  const std::string log = write_log("spy-filter");
  const auto lines =
      spy_on_replay("spy-filtered", log, {"--channel", "SAFETY_(RISK|STATUS)", "--channel", "SPY_PROBE"}, 2);
  EXPECT_EQ(lines, (std::vector<std::string>{kExpectedLines[2], kExpectedLines[3]}));
}

TEST(Spy, StatusBoardShowsPermissionRiskHeartbeatsRatesAndLatency) {
  spy::StatusBoard board;
  const int64_t t0_us = 5'000'000;
  const int64_t utime0 = 1700000000123456;
  for (const auto& [channel, bytes] : log_events()) {
    board.on_message(channel, bytes.data(), static_cast<int>(bytes.size()), t0_us, utime0 + 25'000);
  }
  const std::string text = board.render(t0_us + 100'000, utime0 + 125'000);
  EXPECT_NE(text.find("PERMISSION TO MOVE: NO (software stop, latched, cause joint error)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("DANGEROUS: joint error, suspect a4"), std::string::npos) << text;
  EXPECT_NE(text.find("RISK: DANGEROUS joint error, suspect a4  (frame seq 42"), std::string::npos) << text;
  EXPECT_NE(text.find("tofguard-renderer"), std::string::npos) << text;
  EXPECT_NE(text.find("dropped 2 decode_err 3 invalid 4 | running"), std::string::npos) << text;
  // One TOF_DEPTH in the 2 s window: 0.5 Hz; captured 25 ms before arrival.
  EXPECT_NE(text.find("TOF_DEPTH                 0.5 Hz   latency 25.0 ms"), std::string::npos) << text;

  // Without a fresh status the board says so.
  const std::string later = board.render(t0_us + 1'000'000, utime0);
  EXPECT_NE(later.find("STALE"), std::string::npos) << later;
  EXPECT_NE(later.find("MISSING"), std::string::npos) << later;
}

// With two cameras the board shows each: its frame rate, its last frame's
// age, and the latest verdict that named it.
TEST(Spy, StatusBoardShowsEachCamera) {
  spy::StatusBoard board;
  const int64_t t0_us = 5'000'000;
  for (const std::string id : {"tof-mast", "tof-side"}) {
    depth_image_t image = sample_depth_image();
    image.camera_id = id;
    const std::vector<uint8_t> bytes = encoded(image);
    board.on_message("TOF_DEPTH", bytes.data(), static_cast<int>(bytes.size()), t0_us, 0);
  }
  risk_t verdict = sample_risk();
  verdict.level = risk_t::DANGEROUS;
  verdict.detail = "tof-side: timeout: TOF_DEPTH/tof-side stale";
  const std::vector<uint8_t> bytes = encoded(verdict);
  board.on_message("SAFETY_RISK", bytes.data(), static_cast<int>(bytes.size()), t0_us + 100'000, 0);
  const std::string text = board.render(t0_us + 300'000, 0);
  EXPECT_NE(text.find("CAMERAS"), std::string::npos) << text;
  EXPECT_NE(text.find("tof-mast       0.5 Hz, last frame 0.30 s STALE\n"), std::string::npos) << text;
  EXPECT_NE(text.find("tof-side       0.5 Hz, last frame 0.30 s STALE, DANGEROUS 0.20 s ago: timeout: "
                      "TOF_DEPTH/tof-side stale"),
            std::string::npos)
      << text;
}

}  // namespace
}  // namespace tofguard::test

namespace tofguard::test {
namespace {

// A signed envelope (docs/security.md) shows what it claims to carry; the
// spy holds no key and says it did not check the tag.
TEST(MessageFormat, ASignedEnvelopeShowsItsChannelSeqKeyAndPayloadType) {
  safety_status_t status{};
  status.reason = "x";
  authenticated_message_t m{};
  m.utime = 1;
  m.seq = 1700000000000005;
  m.channel = "SAFETY_STATUS";
  m.key_id = "0123456789abcdef";
  m.payload.resize(static_cast<size_t>(status.getEncodedSize()));
  status.encode(m.payload.data(), 0, static_cast<int>(m.payload.size()));
  m.payload_size = static_cast<int32_t>(m.payload.size());
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  EXPECT_EQ(spy::format_message("SAFETY_STATUS_AUTH", bytes.data(), static_cast<int>(bytes.size())),
            "SAFETY_STATUS_AUTH authenticated_message_t for=SAFETY_STATUS seq=1700000000000005 "
            "key=0123456789abcdef payload=safety_status_t (" +
                std::to_string(m.payload.size()) + " bytes, tag not checked)");
}

// The speed limit (speed_limit_t): one decoded line, and on the board what
// set it, how far, and when it no longer holds.
TEST(MessageFormat, TheSpeedLimitShowsWhatSetItAndTheBoardWhenItExpires) {
  speed_limit_t limit{};
  limit.utime = 1700000000123456;
  limit.seq = 42;
  limit.camera_id = "tof-mast";
  limit.max_arm_speed_m_s = 0.62;
  limit.set_by = speed_limit_t::SET_BY_UNKNOWN_OBJECT;
  limit.separation_m = 0.9;
  limit.arm_speed_m_s = 0.25;
  limit.valid_for_ms = 150;
  limit.reason = "unknown object 0.90 m from the arm: S fits up to 0.62 m/s";
  std::vector<uint8_t> bytes(static_cast<size_t>(limit.getEncodedSize()));
  limit.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  EXPECT_EQ(
      spy::format_message("SAFETY_SPEED_LIMIT", bytes.data(), static_cast<int>(bytes.size())),
      "SAFETY_SPEED_LIMIT speed_limit_t utime=1700000000123456 seq=42 max_arm_speed=0.62 m/s "
      "set_by=unknown object separation=0.90 m arm_speed=0.25 m/s valid_for=150 ms | unknown object 0.90 "
      "m from the arm: S fits up to 0.62 m/s");
  spy::StatusBoard board;
  board.on_message("SAFETY_SPEED_LIMIT", bytes.data(), static_cast<int>(bytes.size()), 1'000'000,
                   limit.utime);
  const std::string fresh = board.render(1'100'000, limit.utime);
  EXPECT_NE(
      fresh.find("SPEED LIMIT: 0.62 m/s, set by unknown object at 0.90 m  (arm at 0.25 m/s, age 0.10 s)"),
      std::string::npos)
      << fresh;
  const std::string later = board.render(1'200'000, limit.utime);
  EXPECT_NE(later.find("EXPIRED: 0 m/s"), std::string::npos) << later;
}

}  // namespace
}  // namespace tofguard::test
