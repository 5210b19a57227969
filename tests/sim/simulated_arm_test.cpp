#include <gtest/gtest.h>

#include <cmath>

#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/sim/simulated_arm.hpp"
#include "tool_support.hpp"

namespace tofguard::sim {
namespace {

JointsSimSettings two_joints() {
  JointsSimSettings c;
  c.rate_hz = 100;
  c.status_deadline_us = 100000;
  c.motion = {{"j2", 0.5, 0.2, 4.0, 0.0}, {"j1", -1.0, 0.0, 1.0, 0.0}};
  c.faults = {{"j2", 0.1745, 2.0}};
  return c;
}

TEST(SimulatedArm, FollowsItsMotionOnlyWhileAllowed) {
  SimulatedArm arm(two_joints(), {"j1", "j2"}, "test.yaml");
  // URDF order, not config order.
  EXPECT_EQ(arm.true_state().name, (std::vector<std::string>{"j1", "j2"}));
  EXPECT_DOUBLE_EQ(arm.true_state().position[1], 0.5);
  arm.step(1.0, true);  // a quarter period: at the top of the sine, velocity 0
  EXPECT_NEAR(arm.true_state().position[1], 0.7, 1e-12);
  EXPECT_NEAR(arm.true_state().velocity[1], 0.0, 1e-12);
  arm.step(1.0, true);  // half a period: back at the centre, fastest downwards
  EXPECT_NEAR(arm.true_state().position[1], 0.5, 1e-12);
  EXPECT_NEAR(arm.true_state().velocity[1], -0.2 * 2 * M_PI / 4.0, 1e-12);
  EXPECT_DOUBLE_EQ(arm.true_state().position[0], -1.0);

  // Halted: position held, velocity 0, motion time stands still.
  arm.step(0.5, false);
  EXPECT_NEAR(arm.true_state().position[1], 0.5, 1e-12);
  EXPECT_EQ(arm.true_state().velocity[1], 0.0);
  EXPECT_FALSE(arm.moving());
  arm.step(1.0, true);  // resumes where it stopped: three quarters -> bottom
  EXPECT_NEAR(arm.true_state().position[1], 0.3, 1e-12);
}

TEST(SimulatedArm, EncoderFaultsChangeOnlyTheReportedPosition) {
  SimulatedArm arm(two_joints(), {"j1", "j2"}, "test.yaml");
  arm.step(1.99, false);
  EXPECT_DOUBLE_EQ(arm.reported_state().position[1], arm.true_state().position[1]);
  arm.step(0.02, false);  // the scheduled fault at 2 s
  EXPECT_NEAR(arm.reported_state().position[1] - arm.true_state().position[1], 0.1745, 1e-12);
  EXPECT_DOUBLE_EQ(arm.reported_state().position[0], arm.true_state().position[0]);
  EXPECT_TRUE(arm.set_encoder_offset("j1", -0.05));
  EXPECT_NEAR(arm.reported_state().position[0] - arm.true_state().position[0], -0.05, 1e-12);
  EXPECT_TRUE(arm.set_encoder_offset("j2", 0.0));
  EXPECT_DOUBLE_EQ(arm.reported_state().position[1], arm.true_state().position[1]);
  EXPECT_FALSE(arm.set_encoder_offset("j9", 1.0));
}

// A drive (a controller fault): the joint moves at its speed on top of
// the motion, unscaled, only while allowed, and in the plan; ended, the
// joint comes back to its motion at the fixed controller's pace.
TEST(SimulatedArm, ADrivenJointMovesAtItsSpeedOnTopOfTheMotion) {
  SimulatedArm arm(two_joints(), {"j1", "j2"}, "test.yaml");
  EXPECT_EQ(arm.task_stage(), "");  // no task
  const int plan_version = arm.plan_version();
  EXPECT_FALSE(arm.set_drive("j9", 1.0));
  EXPECT_EQ(arm.plan_version(), plan_version);
  ASSERT_TRUE(arm.set_drive("j1", 0.5));
  EXPECT_EQ(arm.plan_version(), plan_version + 1);
  arm.step(0.4, true, 0.25);  // j1's motion stands (amplitude 0)
  EXPECT_NEAR(arm.true_state().position[0], -1.0 + 0.2, 1e-12);
  EXPECT_NEAR(arm.true_state().velocity[0], 0.5, 1e-12);
  EXPECT_NEAR(arm.planned_reported_positions(0.2)[0], -1.0 + 0.3, 1e-12);
  arm.step(1.0, false);  // halted: the drive stops too
  EXPECT_NEAR(arm.true_state().position[0], -0.8, 1e-12);
  EXPECT_EQ(arm.true_state().velocity[0], 0.0);
  EXPECT_NEAR(arm.planned_reported_positions(0.2)[0], -0.8, 1e-12);
  // Ended: the fixed controller brings j1 back to its motion at 0.25 rad/s
  // x the speed scale.
  ASSERT_TRUE(arm.set_drive("", 0.0));
  arm.step(0.4, true, 0.5);
  EXPECT_NEAR(arm.true_state().position[0], -0.85, 1e-12);
  EXPECT_NEAR(arm.true_state().velocity[0], -0.125, 1e-12);
  EXPECT_NEAR(arm.planned_reported_positions(0.4)[0], -0.9, 1e-12);
  EXPECT_NEAR(arm.planned_reported_positions(10)[0], -1.0, 1e-12);
  arm.step(1.0, true);
  EXPECT_NEAR(arm.true_state().position[0], -1.0, 1e-12);
  EXPECT_EQ(arm.true_state().velocity[0], 0.0);
}

// The task: hold at each waypoint, then a cosine move to the next (at rest
// at both ends, fastest half way: pi/2 x the mean speed), the last back to
// the first; a slowed arm takes longer along the same path.
TEST(SimulatedArm, FollowsItsTaskWaypointsInACycle) {
  JointsSimSettings c = two_joints();
  c.task_move_s = 2.0;
  c.task_waypoints = {{"table", 1.0, {{"j1", 0.0}, {"j2", 0.0}}},
                      {"mouth", 0.5, {{"j1", 1.0}, {"j2", -0.4}}}};
  SimulatedArm arm(c, {"j1", "j2"}, "test.yaml", /*task=*/true);
  EXPECT_DOUBLE_EQ(arm.true_state().position[0], 0.0);
  arm.step(0.9, true);  // holding at the table
  EXPECT_DOUBLE_EQ(arm.true_state().position[0], 0.0);
  EXPECT_EQ(arm.task_stage(), "at table");
  EXPECT_DOUBLE_EQ(arm.true_state().velocity[0], 0.0);
  arm.step(1.1, true);  // t = 2.0: half way to the mouth, fastest
  EXPECT_NEAR(arm.true_state().position[0], 0.5, 1e-12);
  EXPECT_NEAR(arm.true_state().position[1], -0.2, 1e-12);
  EXPECT_NEAR(arm.true_state().velocity[0], M_PI / 2 * 1.0 / 2.0, 1e-12);
  EXPECT_EQ(arm.task_stage(), "to mouth");
  arm.step(1.0, true, 0.5);  // at half speed: a quarter of the move more
  EXPECT_NEAR(arm.true_state().position[0], (1 - std::cos(M_PI * 0.75)) / 2, 1e-12);
  EXPECT_NEAR(arm.true_state().velocity[0], 0.5 * M_PI / 4 * std::sin(M_PI * 0.75), 1e-12);
  arm.step(0.5 + 0.5, true);  // t = 3.5: at the mouth, holding
  EXPECT_NEAR(arm.true_state().position[0], 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(arm.true_state().velocity[0], 0.0);
  arm.step(1.0, true);  // t = 4.5: half way back to the table
  EXPECT_NEAR(arm.true_state().position[0], 0.5, 1e-12);
  EXPECT_NEAR(arm.true_state().velocity[0], -M_PI / 4, 1e-12);
  EXPECT_EQ(arm.task_stage(), "to table");
  arm.step(1.5, true);  // t = 6.0, 0.5 s into the next cycle: holding at the table
  EXPECT_NEAR(arm.true_state().position[0], 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(arm.true_state().velocity[0], 0.0);
}

TEST(SimulatedArm, ATaskMustGiveEveryJointAtEveryWaypoint) {
  JointsSimSettings c = two_joints();
  EXPECT_THROW(SimulatedArm(c, {"j1", "j2"}, "test.yaml", true), ConfigError);  // no task
  c.task_move_s = 1.0;
  c.task_waypoints = {{"table", 1.0, {{"j1", 0.0}, {"j2", 0.0}}}, {"mouth", 1.0, {{"j1", 1.0}}}};
  try {
    SimulatedArm arm(c, {"j1", "j2"}, "test.yaml", true);
    FAIL() << "accepted a waypoint without j2";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("joints_sim.task.waypoints[mouth].joints"), std::string::npos)
        << e.what();
  }
}

TEST(SimulatedArm, MotionMustCoverExactlyTheUrdfJoints) {
  auto message = [](const JointsSimSettings& c, const std::vector<std::string>& joints) {
    try {
      SimulatedArm arm(c, joints, "cfg.yaml");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(
      message(two_joints(), {"j1", "j2", "j3"}),
      "cfg.yaml: joints_sim.motion: expected an entry for every movable joint of the URDF (j1, j2, j3), "
      "missing j3");
  EXPECT_EQ(message(two_joints(), {"j2"}),
            "cfg.yaml: joints_sim.motion.j1: unknown joint, expected one of the URDF's movable joints: j2");
  JointsSimSettings bad_fault = two_joints();
  bad_fault.faults[0].joint = "j7";
  EXPECT_EQ(message(bad_fault, {"j1", "j2"}),
            "cfg.yaml: joints_sim.faults: unknown joint 'j7', expected one of: j1, j2");
}

}  // namespace
}  // namespace tofguard::sim
