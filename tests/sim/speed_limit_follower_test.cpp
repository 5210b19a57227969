// The simulated arm's controller following SAFETY_SPEED_LIMIT: what each
// limit does to the speed scale, worked by hand.
#include <gtest/gtest.h>

#include "tofguard/sim/speed_limit_follower.hpp"

namespace tofguard::sim {
namespace {

constexpr int64_t kMs = 1000;

speed_limit_t limit(double max_m_s, double arm_m_s, int64_t utime) {
  speed_limit_t l{};
  l.utime = utime;
  l.max_arm_speed_m_s = max_m_s;
  l.arm_speed_m_s = arm_m_s;
  l.valid_for_ms = 150;
  return l;
}

TEST(SpeedLimitFollower, StandsWithoutALimitAndRampsUpWithOne) {
  SpeedLimitFollower f(0.8, 0.5);
  EXPECT_DOUBLE_EQ(f.next_scale(0, 0.01), 0);  // no limit yet: stand
  f.on_limit(limit(1.0, -1, 0), 0);
  // No bound to go by: +0.5 per second.
  EXPECT_NEAR(f.next_scale(10 * kMs, 0.1), 0.05, 1e-12);
  EXPECT_NEAR(f.next_scale(20 * kMs, 0.1), 0.10, 1e-12);
}

TEST(SpeedLimitFollower, KeepsTheBoundAtTheMarginOfTheLimit) {
  SpeedLimitFollower f(0.8, 0.5);
  // Joint states at full speed, then the limit of one of them: the arm at
  // 1.0 m/s, limit 0.4 m/s -> scale 0.8 * 0.4 / 1.0 = 0.32 (from a
  // stand, after the ramp's 0.64 s).
  f.on_joint_state(100 * kMs, 1.0);
  f.on_joint_state(110 * kMs, 1.0);
  f.on_limit(limit(0.4, 1.0, 105 * kMs), 0);
  EXPECT_NEAR(f.next_scale(1 * kMs, 0.01), 0.005, 1e-12);
  EXPECT_NEAR(f.next_scale(1 * kMs, 1.0), 0.32, 1e-12);
  // A lower limit takes effect at once: 0.8 * 0.2 / 1.0.
  f.on_limit(limit(0.2, 1.0, 105 * kMs), 1 * kMs);
  EXPECT_NEAR(f.next_scale(1 * kMs, 0.01), 0.16, 1e-12);
  f.on_limit(limit(0.4, 1.0, 105 * kMs), 1 * kMs);
  EXPECT_NEAR(f.next_scale(1 * kMs, 1.0), 0.32, 1e-12);
  // A limit computed on a joint state slowed to 0.32: the arm at 0.3 m/s
  // there is 0.9375 m/s at full speed; the limit rises to 0.6 m/s ->
  // 0.8 * 0.6 / 0.9375 = 0.512, reached by the ramp only.
  f.on_joint_state(140 * kMs, 0.32);
  f.on_limit(limit(0.6, 0.3, 145 * kMs), 2 * kMs);
  EXPECT_NEAR(f.next_scale(3 * kMs, 0.1), 0.37, 1e-12);
  EXPECT_NEAR(f.next_scale(4 * kMs, 1.0), 0.512, 1e-12);
}

TEST(SpeedLimitFollower, StandsOnAZeroOrExpiredLimit) {
  SpeedLimitFollower f(0.8, 0.5);
  f.on_joint_state(100 * kMs, 1.0);
  f.on_limit(limit(0.4, 0.2, 100 * kMs), 0);
  EXPECT_GT(f.next_scale(150 * kMs, 0.01), 0);
  EXPECT_DOUBLE_EQ(f.next_scale(151 * kMs, 0.01), 0);  // 150 ms valid: expired
  f.on_limit(limit(0.0, 0.2, 100 * kMs), 200 * kMs);
  EXPECT_DOUBLE_EQ(f.next_scale(201 * kMs, 0.01), 0);
}

}  // namespace
}  // namespace tofguard::sim
