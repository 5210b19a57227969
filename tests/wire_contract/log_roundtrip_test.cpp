// C++ publisher -> lcm-logger -> log file -> lcm-logplayer -> C++ subscriber,
// over real UDP multicast inside a private network namespace, with every
// field compared. The log is kept in the test-output folder for
// DecodeLog.java (the Java side of the same check).
#include <gtest/gtest.h>
#include <signal.h>
#include <lcm/lcm-cpp.hpp>

#include <filesystem>
#include <map>
#include <set>
#include <thread>
#include <vector>

#include "sample_messages.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

constexpr const char* kUrl = "udpm://239.255.76.67:7667?ttl=0";
constexpr const char* kProbeChannel = "ROUNDTRIP_PROBE";

// Every message of the wire contract, encoded, by channel.
std::map<std::string, std::vector<uint8_t>> sample_payloads() {
  return {
      {"TOF_DEPTH", encoded(sample_depth_image())},
      {"JOINT_STATE", encoded(sample_joint_state())},
      {"CAMERA_POSE", encoded(sample_camera_pose())},
      {"SAFETY_RISK", encoded(sample_risk())},
      {"SAFETY_STATUS", encoded(sample_safety_status())},
      {"TOF_LABELS", encoded(sample_link_labels())},
      {"SAFETY_HEARTBEAT", encoded(sample_heartbeat())},
      {"SAFETY_RESET", encoded(sample_reset_request())},
      {"SAFETY_RESET_REPLY", encoded(sample_reset_reply())},
  };
}

std::set<std::string> channels_in_log(const std::string& path) {
  std::set<std::string> channels;
  lcm::LogFile log(path, "r");
  if (!log.good()) return channels;
  while (const lcm::LogEvent* event = log.readNextEvent()) channels.insert(event->channel);
  return channels;
}

int events_in_log(const std::string& path, const std::string& channel) {
  int count = 0;
  lcm::LogFile log(path, "r");
  if (!log.good()) return 0;
  while (const lcm::LogEvent* event = log.readNextEvent()) count += event->channel == channel;
  return count;
}

struct Collector {
  std::map<std::string, std::vector<uint8_t>> received;
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const auto* data = static_cast<const uint8_t*>(rbuf->data);
    received[channel] = std::vector<uint8_t>(data, data + rbuf->data_size);
  }
};

template <class T>
T decode_as(const std::vector<uint8_t>& bytes) {
  T message;
  EXPECT_EQ(message.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return message;
}

TEST(LogRoundTrip, EveryFieldSurvivesLoggerAndPlayer) {
  const std::string log_path = output_dir() + "/roundtrip.lcmlog";
  std::filesystem::remove(log_path);
  const auto payloads = sample_payloads();

  lcm::LCM publisher(kUrl);
  ASSERT_TRUE(publisher.good());

  // 1. Record: publish a probe until the logger has written it (so the
  //    logger is surely subscribed), then every sample once.
  {
    Subprocess logger("roundtrip-logger", {"/usr/bin/lcm-logger", std::string("--lcm-url=") + kUrl,
                                           "--flush-interval=10", "-f", log_path});
    const uint8_t probe = 1;
    ASSERT_TRUE(wait_until(
        [&] {
          publisher.publish(kProbeChannel, &probe, 1);
          // 25 probes (about 500 ms) ahead of the samples: lcm-logplayer
          // 1.3.1 may drop the first events it reads (see below).
          return events_in_log(log_path, kProbeChannel) >= 25;
        },
        std::chrono::seconds(10), [] { std::this_thread::sleep_for(std::chrono::milliseconds(20)); }))
        << "lcm-logger never recorded the probe: " << logger.stderr_text();
    for (const auto& [channel, bytes] : payloads) {
      ASSERT_EQ(publisher.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size())), 0);
    }
    // lcm-logger flushes only when a message arrives after its flush
    // interval, so keep the probe going until the samples are on disk.
    ASSERT_TRUE(wait_until(
        [&] {
          publisher.publish(kProbeChannel, &probe, 1);
          const auto logged = channels_in_log(log_path);
          for (const auto& entry : payloads) {
            if (!logged.count(entry.first)) return false;
          }
          return true;
        },
        std::chrono::seconds(10), [] { std::this_thread::sleep_for(std::chrono::milliseconds(20)); }))
        << "not every channel reached the log";
    logger.signal(SIGINT);
    EXPECT_EQ(logger.wait(std::chrono::seconds(10)), 0) << logger.stderr_text();
  }

  // 2. Replay as fast as possible into a subscriber.
  lcm::LCM subscriber(kUrl);
  ASSERT_TRUE(subscriber.good());
  Collector collector;
  for (const auto& entry : payloads) {
    subscriber.subscribe(entry.first, &Collector::on_message, &collector);
  }
  Subprocess player("roundtrip-player",
                    {"/usr/bin/lcm-logplayer", std::string("--lcm-url=") + kUrl, "-s", "1", log_path});
  ASSERT_TRUE(wait_until([&] { return collector.received.size() == payloads.size(); },
                         std::chrono::seconds(10), [&] { subscriber.handleTimeout(50); }))
      << "received " << collector.received.size() << " of " << payloads.size() << " channels; "
      << player.stderr_text();
  EXPECT_EQ(player.wait(std::chrono::seconds(10)), 0);

  // 3. Every field of the five fixed types, one by one.
  const auto depth = decode_as<depth_image_t>(collector.received["TOF_DEPTH"]);
  const auto depth_sent = sample_depth_image();
  EXPECT_EQ(depth.utime, depth_sent.utime);
  EXPECT_EQ(depth.seq, depth_sent.seq);
  EXPECT_EQ(depth.camera_id, depth_sent.camera_id);
  EXPECT_EQ(depth.width, depth_sent.width);
  EXPECT_EQ(depth.height, depth_sent.height);
  EXPECT_EQ(depth.fx, depth_sent.fx);
  EXPECT_EQ(depth.fy, depth_sent.fy);
  EXPECT_EQ(depth.cx, depth_sent.cx);
  EXPECT_EQ(depth.cy, depth_sent.cy);
  EXPECT_EQ(depth.calibrated, depth_sent.calibrated);
  EXPECT_EQ(depth.num_pixels, depth_sent.num_pixels);
  EXPECT_EQ(depth.depth_mm, depth_sent.depth_mm);
  EXPECT_EQ(depth.num_amplitude, depth_sent.num_amplitude);
  EXPECT_EQ(depth.amplitude, depth_sent.amplitude);

  const auto joints = decode_as<joint_state_t>(collector.received["JOINT_STATE"]);
  const auto joints_sent = sample_joint_state();
  EXPECT_EQ(joints.utime, joints_sent.utime);
  EXPECT_EQ(joints.robot_id, joints_sent.robot_id);
  EXPECT_EQ(joints.num_joints, joints_sent.num_joints);
  EXPECT_EQ(joints.name, joints_sent.name);
  EXPECT_EQ(joints.position, joints_sent.position);
  EXPECT_EQ(joints.velocity, joints_sent.velocity);

  const auto pose = decode_as<camera_pose_t>(collector.received["CAMERA_POSE"]);
  const auto pose_sent = sample_camera_pose();
  EXPECT_EQ(pose.utime, pose_sent.utime);
  EXPECT_EQ(pose.camera_id, pose_sent.camera_id);
  EXPECT_EQ(pose.frame_id, pose_sent.frame_id);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(pose.translation[i], pose_sent.translation[i]);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(pose.rotation[i], pose_sent.rotation[i]);

  const auto risk = decode_as<risk_t>(collector.received["SAFETY_RISK"]);
  const auto risk_sent = sample_risk();
  EXPECT_EQ(risk.utime, risk_sent.utime);
  EXPECT_EQ(risk.seq, risk_sent.seq);
  EXPECT_EQ(risk.level, risk_sent.level);
  EXPECT_EQ(risk.cause, risk_sent.cause);
  EXPECT_EQ(risk.suspect, risk_sent.suspect);
  EXPECT_EQ(risk.score, risk_sent.score);
  EXPECT_EQ(risk.threshold, risk_sent.threshold);
  EXPECT_EQ(risk.detail, risk_sent.detail);

  const auto status = decode_as<safety_status_t>(collector.received["SAFETY_STATUS"]);
  const auto status_sent = sample_safety_status();
  EXPECT_EQ(status.utime, status_sent.utime);
  EXPECT_EQ(status.seq, status_sent.seq);
  EXPECT_EQ(status.motion_allowed, status_sent.motion_allowed);
  EXPECT_EQ(status.stop, status_sent.stop);
  EXPECT_EQ(status.latched, status_sent.latched);
  EXPECT_EQ(status.cause, status_sent.cause);
  EXPECT_EQ(status.reason, status_sent.reason);
  EXPECT_EQ(status.since_utime, status_sent.since_utime);

  // Our own types: the received bytes are exactly the sent encoding.
  for (const char* channel : {"TOF_LABELS", "SAFETY_HEARTBEAT", "SAFETY_RESET", "SAFETY_RESET_REPLY"}) {
    EXPECT_EQ(collector.received[channel], payloads.at(channel)) << channel;
  }
}

}  // namespace
}  // namespace tofguard::test
