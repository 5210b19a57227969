// The five fixed types' fingerprints are public API: other clients (Java,
// Python, lcm-spy, recorded logs) check them.
#include <gtest/gtest.h>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"

TEST(Fingerprint, FixedTypesMatchTheContract) {
  EXPECT_EQ(tofguard::depth_image_t::getHash(), 0x1b848c37a74a6951ULL);
  EXPECT_EQ(tofguard::joint_state_t::getHash(), 0x3c8a665daf35440aULL);
  EXPECT_EQ(tofguard::camera_pose_t::getHash(), 0xcd16d98a11deabd9ULL);
  EXPECT_EQ(tofguard::risk_t::getHash(), 0xb38671149e9efe19ULL);
  EXPECT_EQ(tofguard::safety_status_t::getHash(), 0x47a089c6d448a345ULL);
}

TEST(Fingerprint, EnumConstantsMatchTheContract) {
  using tofguard::risk_t;
  using tofguard::safety_status_t;
  EXPECT_EQ(risk_t::SAFE, 0);
  EXPECT_EQ(risk_t::WARNING, 1);
  EXPECT_EQ(risk_t::DANGEROUS, 2);
  EXPECT_EQ(risk_t::CAUSE_NONE, 0);
  EXPECT_EQ(risk_t::CAUSE_JOINT_ERROR, 1);
  EXPECT_EQ(risk_t::CAUSE_CALIBRATION_ERROR, 2);
  EXPECT_EQ(risk_t::CAUSE_UNKNOWN_OBJECT, 3);
  EXPECT_EQ(risk_t::CAUSE_SENSOR_FAULT, 4);
  EXPECT_EQ(risk_t::CAUSE_COMPONENT_FAULT, 5);
  EXPECT_EQ(risk_t::CAUSE_UNCLASSIFIED, 6);
  EXPECT_EQ(safety_status_t::STOP_NONE, 0);
  EXPECT_EQ(safety_status_t::STOP_SOFTWARE, 1);
  EXPECT_EQ(safety_status_t::STOP_POWER_CUT, 2);
}
