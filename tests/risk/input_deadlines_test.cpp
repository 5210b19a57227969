// The input deadlines on their own, on an explicit monotonic clock: each
// input's limit, the order in which expired ones are reported, and the
// start counting as the last arrival.
#include <gtest/gtest.h>

#include "tofguard/risk/input_deadlines.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::test {
namespace {

using risk::InputDeadlines;
using risk::RiskSettings;

constexpr int64_t kStart = 7'000'000'000;  // monotonic, unrelated to any utime
constexpr int64_t kMs = 1000;

RiskSettings limits() {
  RiskSettings r;
  r.depth_deadline_us = 100 * kMs;
  r.joint_state_deadline_us = 50 * kMs;
  r.discrepancy_deadline_us = 200 * kMs;
  r.heartbeat_deadline_us = 250 * kMs;
  r.camera_pose_required = false;
  r.camera_pose_deadline_us = 1000 * kMs;
  r.required_heartbeats = {"tofguard-renderer", "tofguard-camera"};
  return r;
}

// Every input fresh at `now`.
void touch_all(InputDeadlines* d, int64_t now) {
  d->on_depth(now);
  d->on_joint_state(now);
  d->on_camera_pose(now);
  d->on_discrepancy(now);
  d->on_heartbeat("tofguard-camera", now);
  d->on_heartbeat("tofguard-renderer", now);
}

TEST(InputDeadlines, BeforeAnyArrivalTheDeadlinesRunFromTheStart) {
  InputDeadlines d(limits(), ChannelNames{}, kStart);
  EXPECT_FALSE(d.first_expired(kStart + 50 * kMs).has_value());
  const auto f = d.first_expired(kStart + 50 * kMs + 1);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(f->suspect, "JOINT_STATE");
  EXPECT_DOUBLE_EQ(f->score, 50.001);
  EXPECT_DOUBLE_EQ(f->threshold, 50);
  EXPECT_EQ(f->detail, "JOINT_STATE stale (age ms): nothing since start, 50 ms, deadline 50 ms");
  // Both expired: the camera comes first in the order.
  EXPECT_EQ(d.first_expired(kStart + 101 * kMs)->suspect, "TOF_DEPTH");
}

TEST(InputDeadlines, EachInputHasItsLimitAndCauseInTheDocumentedOrder) {
  InputDeadlines d(limits(), ChannelNames{}, kStart);
  int64_t now = kStart + 1000 * kMs;
  touch_all(&d, now);
  EXPECT_FALSE(d.first_expired(now + 50 * kMs).has_value());

  // Joint state: 50 ms.
  auto f = d.first_expired(now + 51 * kMs);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->suspect, "JOINT_STATE");
  EXPECT_EQ(f->detail, "JOINT_STATE stale (age ms): nothing for 51 ms, deadline 50 ms");

  // Heartbeats by process name (camera before renderer), after the sensors.
  now += 300 * kMs;
  d.on_depth(now);
  d.on_joint_state(now);
  d.on_discrepancy(now);
  d.on_heartbeat("tofguard-discrepancy", now);  // not required: ignored
  f = d.first_expired(now);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->cause, risk_t::CAUSE_COMPONENT_FAULT);
  EXPECT_EQ(f->suspect, "tofguard-camera");
  EXPECT_DOUBLE_EQ(f->score, 300);
  EXPECT_DOUBLE_EQ(f->threshold, 250);
  EXPECT_EQ(f->detail, "tofguard-camera heartbeat stale (age ms): nothing for 300 ms, deadline 250 ms");
  d.on_heartbeat("tofguard-camera", now);
  EXPECT_EQ(d.first_expired(now)->suspect, "tofguard-renderer");
  d.on_heartbeat("tofguard-renderer", now);
  EXPECT_FALSE(d.first_expired(now).has_value());

  // The discrepancy stream last: 200 ms.
  d.on_depth(now + 200 * kMs);
  d.on_joint_state(now + 200 * kMs);
  d.on_heartbeat("tofguard-camera", now + 200 * kMs);
  d.on_heartbeat("tofguard-renderer", now + 200 * kMs);
  EXPECT_FALSE(d.first_expired(now + 200 * kMs).has_value());
  f = d.first_expired(now + 200 * kMs + 1);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->cause, risk_t::CAUSE_COMPONENT_FAULT);
  EXPECT_EQ(f->suspect, "SAFETY_DISCREPANCY");
  EXPECT_EQ(f->detail, "SAFETY_DISCREPANCY stale (age ms): nothing for 200 ms, deadline 200 ms");
}

TEST(InputDeadlines, TheCameraPoseIsWatchedOnlyWhenRequiredWithItsChannelName) {
  ChannelNames channels;
  channels.camera_pose = "HEAD_POSE";
  RiskSettings required_limits = limits();
  required_limits.camera_pose_required = true;
  InputDeadlines optional(limits(), channels, kStart);
  InputDeadlines required(required_limits, channels, kStart);
  // Every input but the pose keeps coming.
  int64_t now = kStart;
  for (; now <= kStart + 1040 * kMs; now += 40 * kMs) {
    for (InputDeadlines* d : {&optional, &required}) {
      d->on_depth(now);
      d->on_joint_state(now);
      d->on_discrepancy(now);
      d->on_heartbeat("tofguard-camera", now);
      d->on_heartbeat("tofguard-renderer", now);
    }
  }
  now -= 40 * kMs;
  EXPECT_FALSE(optional.first_expired(now).has_value());
  const auto f = required.first_expired(now);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(f->suspect, "HEAD_POSE");
  EXPECT_EQ(f->detail, "HEAD_POSE stale (age ms): nothing since start, 1040 ms, deadline 1000 ms");
  required.on_camera_pose(now);
  EXPECT_FALSE(required.first_expired(now).has_value());
}

// The limits are whole microseconds (risk.deadlines_ms rounded once when the
// file is read, YamlMap::milliseconds_as_us), compared as they are.
TEST(InputDeadlines, MicrosecondLimitsAreComparedExactly) {
  RiskSettings r = limits();
  r.depth_deadline_us = 33'333;  // risk.deadlines_ms.depth: 33.3334
  InputDeadlines d(r, ChannelNames{}, kStart);
  touch_all(&d, kStart);
  EXPECT_FALSE(d.first_expired(kStart + 33'333).has_value());
  ASSERT_TRUE(d.first_expired(kStart + 33'334).has_value());
  EXPECT_DOUBLE_EQ(d.first_expired(kStart + 33'334)->threshold, 33.333);
}

}  // namespace
}  // namespace tofguard::test
