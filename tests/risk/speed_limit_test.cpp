// The controller's speed limit per frame (risk/speed_limit.hpp): the
// protective field solved for the arm's speed at the nearest unexplained
// surface, or at the range monitored; 0 wherever there is nothing to size
// it on.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tofguard/risk/protective_field.hpp"
#include "tofguard/risk/speed_limit.hpp"

namespace tofguard::risk::test {
namespace {

// config/sim.yaml's field: S at rest = 1.6 * (T_r + 0.15) + 0.03 + 0.2.
RiskSettings field_settings() {
  RiskSettings risk;
  risk.field_approach_speed_m_s = 1.6;
  risk.field_stopping_time_us = 150'000;
  risk.field_stopping_distance_m = 0.03;
  risk.field_intrusion_distance_m = 0.2;
  risk.unknown_object_min_area_m2 = 0.0015;
  risk.discrepancy_deadline_us = 150'000;
  return risk;
}

// A usable frame with the arm's cover: 200 bins of 1 cm, and `area_m2`
// unexplained from `object_m` outwards (none when negative).
discrepancy_t frame_with_object(double object_m, double area_m2) {
  discrepancy_t f{};
  f.utime = 1'700'000'000'000'000;
  f.seq = 42;
  f.camera_id = "tof-mast";
  f.usable = true;
  f.field_available = true;
  f.field_bin_m = 0.01f;
  f.num_field_bins = 200;
  f.unexplained_area_within_m2.assign(200, 0.0f);
  if (object_m >= 0) {
    for (int k = static_cast<int>(std::lround(object_m / 0.01)) - 1; k < 200; ++k) {
      f.unexplained_area_within_m2[k] = static_cast<float>(area_m2);
    }
  }
  return f;
}

constexpr double kResponseS = 4.0 / 30 + 0.06;  // T_r at 30 Hz, 60 ms latency

TEST(SpeedLimit, ANearObjectSetsItAndNothingNearLeavesTheRange) {
  const RiskSettings risk = field_settings();
  const double at_rest_m = 1.6 * (kResponseS + 0.15) + 0.23;  // 0.7793 m
  const speed_limit_t near = frame_speed_limit(risk, kResponseS, frame_with_object(0.90, 0.01), 0.25);
  EXPECT_EQ(near.set_by, speed_limit_t::SET_BY_UNKNOWN_OBJECT);
  EXPECT_NEAR(near.separation_m, 0.90, 1e-6);
  EXPECT_NEAR(near.max_arm_speed_m_s, (0.90 - at_rest_m) / kResponseS, 1e-5);  // 0.62 m/s
  EXPECT_DOUBLE_EQ(near.arm_speed_m_s, 0.25);
  EXPECT_EQ(near.seq, 42);
  EXPECT_EQ(near.camera_id, "tof-mast");
  EXPECT_EQ(near.valid_for_ms, 150);
  EXPECT_NE(near.reason.find("unknown object 0.90 m from the arm: S fits up to 0.62 m/s"), std::string::npos)
      << near.reason;
  // An arm at exactly the limit has S equal to the separation.
  EXPECT_NEAR(field_size(risk, kResponseS, near.max_arm_speed_m_s).protective_m, 0.90, 1e-5);

  // Smaller than the least object's area: not an object; the range (2 m).
  const speed_limit_t small = frame_speed_limit(risk, kResponseS, frame_with_object(0.90, 0.001), 0.25);
  EXPECT_EQ(small.set_by, speed_limit_t::SET_BY_RANGE);
  EXPECT_DOUBLE_EQ(small.separation_m, -1);
  EXPECT_NEAR(small.max_arm_speed_m_s, (2.0 - at_rest_m) / kResponseS, 1e-5);  // 6.3 m/s

  // Inside S at rest: stand.
  const speed_limit_t inside = frame_speed_limit(risk, kResponseS, frame_with_object(0.50, 0.01), 0.25);
  EXPECT_EQ(inside.set_by, speed_limit_t::SET_BY_UNKNOWN_OBJECT);
  EXPECT_DOUBLE_EQ(inside.max_arm_speed_m_s, 0);
}

TEST(SpeedLimit, NothingToSizeItOnIsZero) {
  const RiskSettings risk = field_settings();
  discrepancy_t unusable = frame_with_object(-1, 0);
  unusable.usable = false;
  unusable.unusable_reason = "no rendering";
  const speed_limit_t a = frame_speed_limit(risk, kResponseS, unusable, 0.1);
  EXPECT_EQ(a.set_by, speed_limit_t::SET_BY_NO_JUDGEMENT);
  EXPECT_DOUBLE_EQ(a.max_arm_speed_m_s, 0);
  EXPECT_NE(a.reason.find("no rendering"), std::string::npos) << a.reason;

  discrepancy_t no_cover = frame_with_object(-1, 0);
  no_cover.field_available = false;
  const speed_limit_t b =
      frame_speed_limit(risk, kResponseS, no_cover, std::numeric_limits<double>::infinity());
  EXPECT_EQ(b.set_by, speed_limit_t::SET_BY_NO_JUDGEMENT);
  EXPECT_DOUBLE_EQ(b.max_arm_speed_m_s, 0);
  EXPECT_DOUBLE_EQ(b.arm_speed_m_s, -1);  // unbounded

  const speed_limit_t stale = stand_still_limit(risk, 123, "tof-mast", "TOF_DEPTH stale");
  EXPECT_EQ(stale.seq, -1);
  EXPECT_EQ(stale.utime, 123);
  EXPECT_DOUBLE_EQ(stale.max_arm_speed_m_s, 0);
  EXPECT_EQ(stale.reason, "stand: TOF_DEPTH stale");
}

}  // namespace
}  // namespace tofguard::risk::test
