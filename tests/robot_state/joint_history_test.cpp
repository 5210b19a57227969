// Joint states at a camera frame's time: interpolation, bounded
// extrapolation, a bounded history.
#include <gtest/gtest.h>

#include "tofguard/robot_state/joint_history.hpp"

namespace tofguard::robot_state {
namespace {

TEST(JointHistory, InterpolatesLinearlyBetweenTheBracketingMessages) {
  JointHistory history(20'000);
  ASSERT_TRUE(history.add(1'000'000, {{"a1", 0.0}, {"a2", 1.0}}));
  ASSERT_TRUE(history.add(1'010'000, {{"a1", 0.1}, {"a2", 0.8}}));
  ASSERT_TRUE(history.add(1'020'000, {{"a1", 0.5}, {"a2", 0.8}}));
  const JointsAtTime j = history.at(1'012'500);
  ASSERT_TRUE(j.usable) << j.unusable_reason;
  EXPECT_NEAR(j.joints.at("a1"), 0.1 + 0.25 * 0.4, 1e-12);
  EXPECT_NEAR(j.joints.at("a2"), 0.8, 1e-12);
  EXPECT_NEAR(history.at(1'005'000).joints.at("a2"), 0.9, 1e-12);
  EXPECT_EQ(history.at(1'010'000).joints.at("a1"), 0.1);
}

TEST(JointHistory, ExtrapolatesOnlyUpToTheLimit) {
  JointHistory history(20'000);
  history.add(1'000'000, {{"a1", 0.0}});
  history.add(1'010'000, {{"a1", 0.1}});
  const JointsAtTime ahead = history.at(1'025'000);  // 15 ms beyond the newest
  ASSERT_TRUE(ahead.usable);
  EXPECT_NEAR(ahead.joints.at("a1"), 0.25, 1e-12);
  const JointsAtTime too_far = history.at(1'030'001);
  EXPECT_FALSE(too_far.usable);
  EXPECT_EQ(too_far.unusable_reason,
            "newest joint state is 20.001000 ms older than the frame (limit 20.000000 ms)");
  EXPECT_TRUE(too_far.joints.empty());
  EXPECT_TRUE(history.at(999'000).usable);  // 1 ms before the oldest: held
  EXPECT_FALSE(history.at(970'000).usable);
}

TEST(JointHistory, EmptyOrOutOfOrder) {
  JointHistory history(20'000);
  EXPECT_EQ(history.at(1).unusable_reason, "no joint state received yet");
  EXPECT_TRUE(history.add(2'000, {{"a1", 1.0}}));
  EXPECT_FALSE(history.add(2'000, {{"a1", 5.0}}));
  EXPECT_FALSE(history.add(1'000, {{"a1", 5.0}}));
  EXPECT_EQ(history.at(2'000).joints.at("a1"), 1.0);
  EXPECT_EQ(history.at(12'000).joints.at("a1"), 1.0);  // one message: held
}

TEST(JointHistory, AJointMissingFromABracketingMessageIsLeftOut) {
  JointHistory history(20'000);
  history.add(1'000, {{"a1", 0.0}, {"a2", 0.0}});
  history.add(2'000, {{"a1", 1.0}});
  const JointsAtTime j = history.at(1'500);
  ASSERT_TRUE(j.usable);
  EXPECT_EQ(j.joints.count("a2"), 0u);  // forward kinematics will name it
  EXPECT_NEAR(j.joints.at("a1"), 0.5, 1e-12);
}

TEST(JointHistory, StaysBounded) {
  JointHistory history(20'000, 1'000'000, 50);
  for (int i = 0; i < 500; ++i) history.add(1'000'000 + i * 1'000, {{"a1", i * 1.0}});
  EXPECT_EQ(history.size(), 50u);
  JointHistory by_time(20'000, 100'000, 1000);
  for (int i = 0; i < 500; ++i) by_time.add(1'000'000 + i * 10'000, {{"a1", i * 1.0}});
  EXPECT_LE(by_time.size(), 12u);
}

}  // namespace
}  // namespace tofguard::robot_state
