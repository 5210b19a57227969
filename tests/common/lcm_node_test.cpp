// LcmNode over real UDP multicast (private network namespace): malformed
// messages are dropped and counted, never handed on; the heartbeat carries
// the counters; timers fire by themselves; the image URL is read only by a
// node that subscribes there.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "sample_messages.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

// The wiring a process gets from the config: both URLs and the default
// channel names.
struct TestWiring {
  LcmSettings lcm;
  ChannelNames channels;
};

TestWiring test_config() {
  TestWiring config;
  config.lcm.url = "udpm://239.255.76.67:7667?ttl=0";
  config.lcm.image_url = derive_image_url(config.lcm.url);
  return config;
}

struct HeartbeatListener {
  heartbeat_t last;
  int count = 0;
  void on_message(const lcm::ReceiveBuffer*, const std::string&, const heartbeat_t* hb) {
    last = *hb;
    ++count;
  }
};

TEST(LcmNode, MalformedMessagesAreCountedAndNeverHandedOn) {
  const TestWiring config = test_config();
  LcmNode node(config.lcm, config.channels, "node-under-test");
  std::vector<depth_image_t> handled;
  node.subscribe<depth_image_t>(
      node.images(), "TOF_DEPTH", [&](const depth_image_t& m) { handled.push_back(m); }, check_depth_image);

  lcm::LCM publisher(config.lcm.image_url);
  ASSERT_TRUE(publisher.good());
  lcm::LCM safety(config.lcm.url);
  HeartbeatListener heartbeats;
  safety.subscribe("SAFETY_HEARTBEAT", &HeartbeatListener::on_message, &heartbeats);

  depth_image_t good = sample_depth_image();
  depth_image_t wrong_size = good;
  wrong_size.num_pixels = 5;
  wrong_size.depth_mm.resize(5);
  joint_state_t other_type = sample_joint_state();  // wrong fingerprint
  std::vector<uint8_t> truncated(good.getEncodedSize());
  good.encode(truncated.data(), 0, static_cast<int>(truncated.size()));
  truncated.resize(truncated.size() / 2);

  publisher.publish("TOF_DEPTH", &wrong_size);
  publisher.publish("TOF_DEPTH", &other_type);
  publisher.publish("TOF_DEPTH", truncated.data(), static_cast<unsigned>(truncated.size()));
  publisher.publish("TOF_DEPTH", &good);

  ASSERT_TRUE(wait_until([&] { return handled.size() == 1 && node.counters().decode_errors == 2; },
                         std::chrono::seconds(5), [&] { node.spin_once(10); }));
  EXPECT_EQ(handled[0].seq, good.seq);
  EXPECT_EQ(handled[0].depth_mm, good.depth_mm);
  EXPECT_EQ(node.counters().frames_in, 1);
  EXPECT_EQ(node.counters().validation_errors, 1);
  EXPECT_NE(node.errors().last().find("TOF_DEPTH"), std::string::npos);

  // The heartbeat reports the same counters.
  ASSERT_TRUE(wait_until([&] { return heartbeats.count > 0 && heartbeats.last.decode_errors == 2; },
                         std::chrono::seconds(5),
                         [&] {
                           node.spin_once(10);
                           safety.handleTimeout(0);
                         }));
  EXPECT_EQ(heartbeats.last.process, "node-under-test");
  EXPECT_EQ(heartbeats.last.frames_in, 1);
  EXPECT_EQ(heartbeats.last.validation_errors, 1);
  EXPECT_GT(heartbeats.last.pid, 0);
}

// The UDP sockets of this network namespace bound to `port` (the test runs
// in a private one: only its own), from /proc/net/udp's local_address
// column ("0100007F:1DF4", the port in hex).
int udp_sockets_bound_to(int port) {
  std::ifstream table("/proc/net/udp");
  std::string line;
  std::getline(table, line);  // the header
  int count = 0;
  while (std::getline(table, line)) {
    std::istringstream fields(line);
    std::string slot;
    std::string local;
    fields >> slot >> local;
    const size_t colon = local.find(':');
    if (colon != std::string::npos && std::stoi(local.substr(colon + 1), nullptr, 16) == port) ++count;
  }
  return count;
}

int port_of(const std::string& udpm_url) {
  const size_t colon = udpm_url.rfind(':');
  return std::stoi(udpm_url.substr(colon + 1));
}

TEST(LcmNode, OnlyANodeSubscribedOnTheImageUrlReceivesThere) {
  const TestWiring config = test_config();
  const int image_port = port_of(config.lcm.image_url);
  ASSERT_NE(image_port, port_of(config.lcm.url));
  ASSERT_EQ(udp_sockets_bound_to(image_port), 0);
  // A node that publishes images but reads none (a camera, the joint
  // simulator, tofguard-intervene): no socket on the image URL, so the
  // kernel never wakes it with a frame.
  LcmNode publisher_only(config.lcm, config.channels, "publishes-images");
  const depth_image_t frame = sample_depth_image();
  publisher_only.images().publish("TOF_DEPTH", &frame);
  publisher_only.spin_once(0);
  EXPECT_EQ(udp_sockets_bound_to(image_port), 0);
  // Nor on the safety URL, where it reads nothing either (its heartbeat
  // goes out all the same).
  EXPECT_EQ(udp_sockets_bound_to(port_of(config.lcm.url)), 0);
  // Subscribing there joins at once: the first image after the call arrives.
  LcmNode reader(config.lcm, config.channels, "reads-images");
  std::vector<depth_image_t> handled;
  reader.subscribe<depth_image_t>(
      reader.images(), "TOF_DEPTH", [&](const depth_image_t& m) { handled.push_back(m); }, check_depth_image);
  EXPECT_EQ(udp_sockets_bound_to(image_port), 1);
  publisher_only.images().publish("TOF_DEPTH", &frame);
  ASSERT_TRUE(wait_until([&] { return handled.size() == 1; }, std::chrono::seconds(5),
                         [&] { reader.spin_once(10); }));
  EXPECT_EQ(handled[0].seq, frame.seq);
  EXPECT_EQ(udp_sockets_bound_to(port_of(config.lcm.url)), 0);
}

// The same on the safety URL: a node joins it on its first subscription
// there, and receives what is sent after it.
TEST(LcmNode, OnlyANodeSubscribedOnTheSafetyUrlReceivesThere) {
  const TestWiring config = test_config();
  const int safety_port = port_of(config.lcm.url);
  ASSERT_EQ(udp_sockets_bound_to(safety_port), 0);
  LcmNode publisher_only(config.lcm, config.channels, "publishes-joints");
  joint_state_t state;
  state.utime = 1;
  state.robot_id = "arm";
  state.num_joints = 1;
  state.name = {"a1"};
  state.position = {0.5};
  state.velocity = {0.0};
  publisher_only.safety().publish("JOINT_STATE", &state);
  publisher_only.spin_once(0);
  EXPECT_EQ(udp_sockets_bound_to(safety_port), 0);
  LcmNode reader(config.lcm, config.channels, "reads-joints");
  std::vector<joint_state_t> handled;
  reader.subscribe<joint_state_t>(
      reader.safety(), "JOINT_STATE", [&](const joint_state_t& m) { handled.push_back(m); },
      check_joint_state);
  EXPECT_EQ(udp_sockets_bound_to(safety_port), 1);
  EXPECT_EQ(udp_sockets_bound_to(port_of(config.lcm.image_url)), 0);
  state.utime = 2;
  publisher_only.safety().publish("JOINT_STATE", &state);
  ASSERT_TRUE(wait_until([&] { return handled.size() == 1; }, std::chrono::seconds(5),
                         [&] { reader.spin_once(10); }));
  EXPECT_EQ(handled[0].utime, 2);
}

TEST(LcmNode, HeartbeatsComeAtTheirRateWithoutAnyTraffic) {
  const TestWiring config = test_config();
  LcmNode node(config.lcm, config.channels, "quiet-node", /*heartbeat_rate_hz=*/20);
  lcm::LCM safety(config.lcm.url);
  HeartbeatListener heartbeats;
  safety.subscribe("SAFETY_HEARTBEAT", &HeartbeatListener::on_message, &heartbeats);
  const int64_t start_us = monotonic_us();
  ASSERT_TRUE(wait_until([&] { return heartbeats.count >= 10; }, std::chrono::seconds(5),
                         [&] {
                           node.spin_once(10);
                           safety.handleTimeout(0);
                         }));
  // 10 heartbeats at 20 Hz take about 450 ms; consecutive seq numbers.
  EXPECT_GE(monotonic_us() - start_us, 400'000);
  EXPECT_EQ(heartbeats.last.seq, heartbeats.count - 1);
}

TEST(LcmNode, TimersFireWhileNothingArrives) {
  LcmNode node(test_config().lcm, ChannelNames{}, "timer-node");
  int ticks = 0;
  node.add_timer(10'000, [&] { ++ticks; });
  const int64_t start_us = monotonic_us();
  ASSERT_TRUE(wait_until([&] { return ticks >= 10; }, std::chrono::seconds(5), [&] { node.spin_once(100); }));
  // Ten ticks of a 10 ms timer cannot come sooner than 100 ms.
  EXPECT_GE(monotonic_us() - start_us, 100'000);
}

}  // namespace
}  // namespace tofguard::test
