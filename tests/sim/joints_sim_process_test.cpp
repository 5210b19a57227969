// tofguard-joints-sim as a real process over real LCM (private network
// namespace): halted without permission, moving with it, halted again when
// the permission goes stale, moving without one only when commissioning;
// following the speed limit; run-time encoder faults.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cmath>

#include "signed_publisher.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/planned_trajectory.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/sim_controller_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"
#include "tofguard/speed_limit_t.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

struct Listener {
  lcm::LCM lcm{"udpm://239.255.76.67:7667?ttl=0"};
  joint_state_t reported, truth;
  std::vector<planned_trajectory_t> plans;
  std::vector<joint_state_t> all_reported;
  int reported_count = 0;
  SignedPublisher signed_lcm{lcm};
  bool allow = false;
  int64_t last_status_us = 0;
  // The speed limit sent with each status (config/sim.yaml's arm follows
  // it), as tofguard-risk would: m/s, and the arm's speed bound of the
  // newest joint state, here the sum of its joint speeds x 1 m.
  double limit_m_s = 100;
  Listener() {
    lcm.subscribe("JOINT_STATE", &Listener::on_reported, this);
    lcm.subscribe("SIM_TRUE_JOINT_STATE", &Listener::on_truth, this);
    lcm.subscribe("PLANNED_TRAJECTORY", &Listener::on_plan, this);
  }
  void on_plan(const lcm::ReceiveBuffer*, const std::string&, const planned_trajectory_t* m) {
    plans.push_back(*m);
  }
  void on_reported(const lcm::ReceiveBuffer*, const std::string&, const joint_state_t* m) {
    reported = *m;
    all_reported.push_back(*m);
    ++reported_count;
  }
  void on_truth(const lcm::ReceiveBuffer*, const std::string&, const joint_state_t* m) { truth = *m; }
  void pump() {
    if (allow && monotonic_us() - last_status_us > 20000) {
      last_status_us = monotonic_us();
      safety_status_t s{};
      s.utime = wall_utime();
      s.motion_allowed = true;
      s.reason = "test";
      signed_lcm.publish("SAFETY_STATUS", s);  // as a keyed tofguard-intervene does
      speed_limit_t limit{};
      limit.utime = reported.utime;
      limit.max_arm_speed_m_s = limit_m_s;
      limit.set_by = speed_limit_t::SET_BY_BODY_REGION;
      limit.arm_speed_m_s = reported_bound_m_s();
      limit.valid_for_ms = 150;
      signed_lcm.publish("SAFETY_SPEED_LIMIT", limit);
    }
    lcm.handleTimeout(5);
  }
  double reported_bound_m_s() const {
    double sum = 0;
    for (double x : reported.velocity) sum += std::abs(x);
    return sum;
  }
  double max_speed() const {
    double v = 0;
    for (double x : reported.velocity) v = std::max(v, std::abs(x));
    return v;
  }
};

TEST(JointsSimProcess, HaltsWithoutPermissionMovesWithItAndInjectsFaults) {
  Subprocess sim("joints-sim",
                 {bin_dir() + "/tofguard-joints-sim", "--config", source_dir() + "/config/sim.yaml"});
  Listener l;
  ASSERT_TRUE(wait_until([&] { return l.reported_count >= 5; }, std::chrono::seconds(5), [&] { l.pump(); }))
      << sim.stderr_text();
  EXPECT_EQ(l.reported.num_joints, 7);
  EXPECT_EQ(l.reported.robot_id, "friend-sim");
  EXPECT_EQ(l.max_speed(), 0.0) << "moves without permission";

  // 100 Hz: 50 messages take at least 490 ms.
  const int64_t start_us = monotonic_us();
  const int start_count = l.reported_count;
  ASSERT_TRUE(wait_until([&] { return l.reported_count >= start_count + 50; }, std::chrono::seconds(5),
                         [&] { l.pump(); }));
  EXPECT_GE(monotonic_us() - start_us, 490000);

  l.allow = true;
  ASSERT_TRUE(wait_until([&] { return l.max_speed() > 0.05; }, std::chrono::seconds(2), [&] { l.pump(); }));

  // Permission goes stale (no status) -> halted within the 100 ms deadline.
  l.allow = false;
  const int64_t silent_since_us = l.last_status_us;
  ASSERT_TRUE(wait_until([&] { return l.max_speed() == 0.0; }, std::chrono::seconds(2), [&] { l.pump(); }));
  EXPECT_LT(monotonic_us() - silent_since_us, 100000 + 50000);

  // Run-time encoder fault: a4 reports 0.1745 rad more than the truth.
  sim_joint_fault_t fault;
  fault.utime = wall_utime();
  fault.joint = "a4";
  fault.offset = 0.1745;
  l.lcm.publish("SIM_JOINT_FAULT", &fault);
  ASSERT_TRUE(wait_until(
      [&] {
        return l.reported.utime == l.truth.utime &&
               std::abs(l.reported.position[3] - l.truth.position[3] - 0.1745) < 1e-9;
      },
      std::chrono::seconds(2), [&] { l.pump(); }));
  EXPECT_EQ(l.reported.position[2], l.truth.position[2]);
}

TEST(JointsSimProcess, PublishesThePlanItFollows) {
  Subprocess sim("joints-sim-plan",
                 {bin_dir() + "/tofguard-joints-sim", "--config", source_dir() + "/config/sim.yaml"});
  Listener l;
  // Halted: the plan holds the arm where it is.
  ASSERT_TRUE(wait_until([&] { return !l.plans.empty(); }, std::chrono::seconds(5), [&] { l.pump(); }))
      << sim.stderr_text();
  const planned_trajectory_t& halted = l.plans.back();
  EXPECT_EQ(halted.num_joints, 7);
  EXPECT_EQ(halted.joint_name[3], "a4");
  ASSERT_EQ(halted.num_points, 26);  // 0..500 ms in 20 ms steps
  EXPECT_EQ(halted.point_utime[25] - halted.point_utime[0], 500'000);
  EXPECT_EQ(halted.point_utime[0], halted.utime);
  EXPECT_EQ(halted.position[0], halted.position[25]);

  // Moving: 10 plans a second, and every reported joint state inside a
  // plan's span is on it (within 0.2 deg: plans follow process time, joint
  // states carry the wall clock).
  l.allow = true;
  ASSERT_TRUE(wait_until([&] { return l.max_speed() > 0.05; }, std::chrono::seconds(2), [&] { l.pump(); }));
  l.plans.clear();
  l.all_reported.clear();
  const int64_t start_us = monotonic_us();
  ASSERT_TRUE(wait_until([&] { return l.plans.size() >= 11; }, std::chrono::seconds(3), [&] { l.pump(); }));
  EXPECT_GE(monotonic_us() - start_us, 900'000);
  EXPECT_NE(l.plans.back().position[0], l.plans.back().position[25]);
  PlannedTrajectory plan;
  int compared = 0;
  size_t next_plan = 0;
  for (const joint_state_t& s : l.all_reported) {
    while (next_plan < l.plans.size() && l.plans[next_plan].utime <= s.utime) plan.add(l.plans[next_plan++]);
    const auto planned = plan.at(s.utime);
    if (!planned) continue;
    ++compared;
    for (int i = 0; i < s.num_joints; ++i) {
      EXPECT_NEAR(s.position[i], planned->at(s.name[i]), 0.2 * M_PI / 180) << s.name[i];
    }
  }
  EXPECT_GT(compared, 50);
}

// config/sim.yaml's arm follows SAFETY_SPEED_LIMIT_AUTH: with a limit of
// 0.3 m/s its bound (here the sum of its joint speeds x 1 m, about 2.7 m/s
// at full speed) stays at 80 % of it, give or take the limit's lag behind
// the arm; with the limit at 0 it stands.
TEST(JointsSimProcess, FollowsTheSpeedLimit) {
  Subprocess sim("joints-sim-speed-limit",
                 {bin_dir() + "/tofguard-joints-sim", "--config", source_dir() + "/config/sim.yaml"});
  Listener l;
  l.allow = true;
  l.limit_m_s = 0.3;
  ASSERT_TRUE(wait_until([&] { return l.max_speed() > 0.01; }, std::chrono::seconds(5), [&] { l.pump(); }))
      << sim.stderr_text();
  // Settled after a second; then two seconds of joint states.
  const int64_t settle_until_us = monotonic_us() + 1'000'000;
  wait_until([&] { return monotonic_us() > settle_until_us; }, std::chrono::seconds(2), [&] { l.pump(); });
  l.all_reported.clear();
  const int64_t end_us = monotonic_us() + 2'000'000;
  wait_until([&] { return monotonic_us() > end_us; }, std::chrono::seconds(3), [&] { l.pump(); });
  ASSERT_GT(l.all_reported.size(), 150u);
  double highest = 0;
  double total = 0;
  for (const joint_state_t& s : l.all_reported) {
    double bound = 0;
    for (double v : s.velocity) bound += std::abs(v);
    highest = std::max(highest, bound);
    total += bound;
  }
  EXPECT_LE(highest, 0.3) << "the arm's bound above the limit";
  EXPECT_GT(total / l.all_reported.size(), 0.1) << "the arm hardly moves under the limit";
  // A controller fault (SIM_CONTROLLER_FAULT): full speed whatever the
  // limit says, then following it again.
  sim_controller_fault_t fault{};
  fault.utime = wall_utime();
  fault.ignore_speed_limit = true;
  l.lcm.publish("SIM_CONTROLLER_FAULT", &fault);
  EXPECT_TRUE(
      wait_until([&] { return l.reported_bound_m_s() > 0.6; }, std::chrono::seconds(5), [&] { l.pump(); }))
      << "the arm kept to the limit";
  fault.ignore_speed_limit = false;
  l.lcm.publish("SIM_CONTROLLER_FAULT", &fault);
  l.limit_m_s = 0;
  ASSERT_TRUE(wait_until([&] { return l.max_speed() == 0.0; }, std::chrono::seconds(1), [&] { l.pump(); }));
}

// --commissioning: the arm moves with no SAFETY_STATUS at all (a camera's
// commissioning recording), and says so in its heartbeat; any other
// argument is a usage error.
TEST(JointsSimProcess, MovesWithoutPermissionOnlyWhenCommissioning) {
  Subprocess sim("joints-sim-commissioning", {bin_dir() + "/tofguard-joints-sim", "--config",
                                              source_dir() + "/config/sim.yaml", "--commissioning"});
  Listener l;
  ASSERT_TRUE(wait_until([&] { return l.max_speed() > 0.05; }, std::chrono::seconds(5), [&] { l.pump(); }))
      << "no motion without a permission: " << sim.stderr_text();
  EXPECT_EQ(l.last_status_us, 0) << "the test published a status";

  std::string out, err;
  EXPECT_EQ(run_command("joints-sim-bad-argument",
                        {bin_dir() + "/tofguard-joints-sim", "--config", source_dir() + "/config/sim.yaml",
                         "--commision"},
                        &out, &err),
            2);
  EXPECT_NE(err.find("unknown argument '--commision' (expected --commissioning or --task)"),
            std::string::npos)
      << err;
}

}  // namespace
}  // namespace tofguard::test
