// The assistive task beside the seated, moving user (config/sim.yaml's
// joints_sim.task, tofguard-joints-sim --task, as scripts/demo runs it):
// the whole chain as real processes brings the cup from the table to the
// user's mouth and back without a stop, the speed limit set by the user's
// regions and lowest near the face; then the arm's controller stops
// following the limit on its way to the mouth (a bad plan at full speed),
// and the chain stops it as faster than the user allows, the face's
// separation never below its clearance (docs/safety-chain.md, "The
// assistive task").
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <iostream>
#include <limits>

#include "live_chain.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/sim_controller_fault_t.hpp"
#include "tofguard/speed_limit_t.hpp"

namespace tofguard::test {
namespace {

// The waypoints' a3 (rad), the joint that moves most: the table's 0, the
// mouth's 1.79.
constexpr double kA3TableRad = 0.0;
constexpr double kA3MouthRad = 1.79;

// What the test watches besides LiveChain's own.
struct TaskWatch {
  explicit TaskWatch(LiveChain* chain) {
    const ChannelNames& ch = chain->config().channels;
    chain->safety().subscribe(ch.joint_state, &TaskWatch::on_joints, this);
    chain->safety().subscribe(ch.speed_limit, &TaskWatch::on_limit, this);
    chain->safety().subscribe(ch.discrepancy, &TaskWatch::on_discrepancy, this);
    face_envelope_m = chain->config().occupant->regions.at(BodyRegion::kFace).envelope_m;
  }
  void on_joints(const lcm::ReceiveBuffer*, const std::string&, const joint_state_t* m) {
    for (int i = 0; i < m->num_joints; ++i) {
      if (m->name[i] != "a3") continue;
      a3_rad = m->position[i];
      a3_rad_s = m->velocity[i];
    }
  }
  void on_limit(const lcm::ReceiveBuffer*, const std::string&, const speed_limit_t* m) {
    if (m->seq < 0) return;
    if (watch_over_limit && first_over_limit_us < 0 && m->arm_speed_m_s > m->max_arm_speed_m_s) {
      first_over_limit_us = monotonic_us();
    }
    if (m->max_arm_speed_m_s < lowest_limit.max_arm_speed_m_s || lowest_limit.seq == 0) lowest_limit = *m;
    ++limits;
    if (m->set_by == speed_limit_t::SET_BY_BODY_REGION) ++limits_by_region;
  }
  void on_discrepancy(const lcm::ReceiveBuffer*, const std::string&, const discrepancy_t* m) {
    for (int k = 0; k < m->num_body_regions; ++k) {
      if (m->body_region[k] != "face") continue;
      face_separation_m = std::min(face_separation_m, m->body_region_separation_m[k] - face_envelope_m);
    }
  }
  double a3_rad = 0, a3_rad_s = 0;
  speed_limit_t lowest_limit{};
  int limits = 0, limits_by_region = 0;
  double face_envelope_m = 0;
  // The face's smallest separation (beyond its envelope) since last reset.
  double face_separation_m = std::numeric_limits<double>::infinity();
  // When watching: the arrival (monotonic) of the first limit the arm's
  // speed bound exceeded (-1: none yet).
  bool watch_over_limit = false;
  int64_t first_over_limit_us = -1;
};

TEST(AssistiveTask, ACycleWithoutAStopThenABadPlanAtTheFaceIsStopped) {
  LiveChain chain("assistive-task", {}, /*start=*/false);
  ASSERT_TRUE(chain.config().occupant.has_value()) << "config/sim.yaml seats no user";
  ASSERT_FALSE(chain.config().joints_sim.task_waypoints.empty()) << "config/sim.yaml has no task";
  chain.arguments["tofguard-joints-sim"] = {"--task"};
  for (const std::string& p : chain_process_names()) chain.start(p);
  TaskWatch watch(&chain);
  chain.bring_to_motion("start of the task");
  if (HasFatalFailure()) return;

  // One cycle: to the mouth, then back to the table (at the limits' pace).
  const int stops_before = chain.stops_seen();
  watch.face_separation_m = std::numeric_limits<double>::infinity();
  watch.lowest_limit = speed_limit_t{};
  watch.limits = 0;
  watch.limits_by_region = 0;
  ASSERT_TRUE(chain.wait([&] { return watch.a3_rad > kA3MouthRad - 0.02; }, std::chrono::seconds(60)))
      << "never at the mouth: a3 " << watch.a3_rad << ", last risk " << chain.describe_last_risk();
  ASSERT_TRUE(chain.wait([&] { return watch.a3_rad < kA3TableRad + 0.02; }, std::chrono::seconds(60)))
      << "never back at the table: a3 " << watch.a3_rad << ", last risk " << chain.describe_last_risk();
  EXPECT_EQ(chain.stops_seen(), stops_before) << chain.describe_last_risk();
  EXPECT_TRUE(chain.motion_allowed());
  std::cout << "one cycle: " << watch.limits << " limits, " << watch.limits_by_region
            << " set by a body region; the lowest " << watch.lowest_limit.max_arm_speed_m_s << " m/s ("
            << watch.lowest_limit.reason << "); the face at least " << watch.face_separation_m
            << " m beyond its envelope" << std::endl;
  EXPECT_GT(watch.limits_by_region, 0);
  EXPECT_GE(watch.face_separation_m,
            chain.config().occupant->regions.at(BodyRegion::kFace).clearance_m.value());

  // The bad plan: on the way to the mouth, the controller ignores the limit.
  ASSERT_TRUE(chain.wait([&] { return watch.a3_rad > 0.3 && watch.a3_rad_s > 0; }, std::chrono::seconds(60)))
      << "never on the way to the mouth";
  sim_controller_fault_t fault{};
  fault.utime = wall_utime();
  fault.ignore_speed_limit = true;
  watch.face_separation_m = std::numeric_limits<double>::infinity();
  watch.watch_over_limit = true;
  const int64_t injected_us = monotonic_us();
  chain.safety().publish(chain.config().channels.sim_controller_fault, &fault);
  ASSERT_TRUE(chain.wait([&] { return !chain.motion_allowed(); }, std::chrono::seconds(5)))
      << "no stop: " << chain.describe_last_risk();
  ASSERT_GE(watch.first_over_limit_us, injected_us) << "stopped, but no limit exceeded";
  // From the first limit the arm exceeded (it goes out with its frame's
  // verdict, so it arrives with the frame's judgement).
  const int64_t latency_us = chain.first_stop_since(injected_us) - watch.first_over_limit_us;
  // The arm keeps what it was at the stop for a while: the separation it
  // reached is in the frames that follow.
  const int64_t settle_until_us = monotonic_us() + 500'000;
  chain.wait([&] { return monotonic_us() > settle_until_us; }, std::chrono::seconds(1));
  const safety_status_t& stop = chain.last_status();
  std::cout << "bad plan: stop " << latency_us / 1000.0 << " ms after the first limit exceeded ("
            << (watch.first_over_limit_us - injected_us) / 1000.0
            << " ms after the controller ignored it): " << stop.reason << "; the face at least "
            << watch.face_separation_m << " m beyond its envelope" << std::endl;
  EXPECT_EQ(risk_cause_name(stop.cause), risk_cause_name(risk_t::CAUSE_UNKNOWN_OBJECT)) << stop.reason;
  EXPECT_NE(stop.reason.find(" from the user's "), std::string::npos) << stop.reason;
  // The debounce's two more frames (67 ms at 30 Hz) and the chain's
  // 200 ms budget.
  EXPECT_LE(latency_us, 300'000);
  EXPECT_GE(watch.face_separation_m,
            chain.config().occupant->regions.at(BodyRegion::kFace).clearance_m.value());
  fault.utime = wall_utime();
  fault.ignore_speed_limit = false;
  chain.safety().publish(chain.config().channels.sim_controller_fault, &fault);
}

}  // namespace
}  // namespace tofguard::test
