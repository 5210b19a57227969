#include "tofguard/sim/joints_sim_process.hpp"

#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/auth/message_verifier.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/sim/simulated_arm.hpp"
#include "tofguard/sim_joint_fault_t.hpp"

namespace tofguard::sim {
namespace {

joint_state_t to_message(const ArmState& state, const std::string& robot_id, int64_t utime) {
  joint_state_t m;
  m.utime = utime;
  m.robot_id = robot_id;
  m.num_joints = static_cast<int32_t>(state.name.size());
  m.name = state.name;
  m.position = state.position;
  m.velocity = state.velocity;
  return m;
}

}  // namespace

ProcessInfo joints_sim_info() {
  return {"tofguard-joints-sim",
          "The simulated arm: publishes JOINT_STATE (reported, with encoder faults) and\n"
          "SIM_TRUE_JOINT_STATE (the truth) at joints_sim.rate_hz, following the periodic\n"
          "motion of the config, and its plan on PLANNED_TRAJECTORY (joints_sim.plan);\n"
          "halts while SAFETY_STATUS withdraws permission or is stale.\n"
          "Encoder faults: joints_sim.faults in the config, or sim_joint_fault_t on SIM_JOINT_FAULT."};
}

int run_joints_sim(const JointsSimProcessSettings& settings) {
  // A URDF that cannot be loaded, or a motion that does not fit it, throws
  // ConfigError: the process runner reports it as a config error (exit
  // code 2). The robot's URDF is part of the configuration.
  std::vector<std::string> urdf_joints;
  try {
    urdf_joints = robot_model::load_kinematic_tree(settings.robot.urdf_path).actuated_joint_names;
  } catch (const robot_model::ModelError& e) {
    throw ConfigError(e.what());
  }
  const auto arm = std::make_unique<SimulatedArm>(settings.joints_sim, urdf_joints, settings.config_file);
  LcmNode node(settings.lcm, settings.channels, "tofguard-joints-sim");

  bool status_allows = false;
  int64_t status_arrival_us = -1;
  auto on_status = [&](const safety_status_t& s) {
    status_allows = s.motion_allowed;
    status_arrival_us = monotonic_us();
  };
  // The simulated arm's controller does what a real one must
  // (docs/security.md): with a key it moves only on a verified
  // SAFETY_STATUS_AUTH; the plain SAFETY_STATUS is not read at all.
  std::optional<auth::MessageVerifier> verifier;
  if (auth::authenticated(settings.auth)) {
    verifier.emplace(settings.auth.key, settings.auth.max_age_us);
    node.subscribe<authenticated_message_t>(
        node.safety(), settings.channels.status_auth, [&](const authenticated_message_t& m) {
          std::string why;
          const auto status =
              verifier->open<safety_status_t>(m, settings.channels.status, wall_utime(), &why);
          if (status && (why = check_safety_status(*status)).empty()) {
            on_status(*status);
            return;
          }
          node.counters().validation_errors++;
          node.errors().report(settings.channels.status_auth,
                               settings.channels.status_auth + ": refused: " + why);
        });
  } else {
    node.subscribe<safety_status_t>(node.safety(), settings.channels.status, on_status, check_safety_status);
  }
  node.subscribe<sim_joint_fault_t>(
      node.safety(), settings.channels.sim_joint_fault,
      [&](const sim_joint_fault_t& fault) {
        if (!arm->set_encoder_offset(fault.joint, fault.offset)) {
          node.counters().validation_errors++;
          node.errors().report(settings.channels.sim_joint_fault,
                               settings.channels.sim_joint_fault +
                                   ": joint: expected a joint of the arm, got '" + fault.joint + "'");
          return;
        }
        std::cerr << "tofguard-joints-sim: encoder fault on " << fault.joint << ": offset " << fault.offset
                  << std::endl;
      },
      check_sim_joint_fault);

  const int64_t period_us = static_cast<int64_t>(1e6 / settings.joints_sim.rate_hz);
  int64_t last_step_us = monotonic_us();
  // The plan: every 1/plan_rate_hz, and at once when the permission to move
  // changes (the arm halts or resumes), from the joint state just published.
  const JointsSimSettings& sim = settings.joints_sim;
  const int64_t plan_period_us = static_cast<int64_t>(1e6 / sim.plan_rate_hz);
  int64_t next_plan_us = 0;
  bool planned_allowed = false;
  int planned_offsets_version = 0;
  auto publish_plan = [&](int64_t utime) {
    planned_trajectory_t plan;
    plan.utime = utime;
    plan.joint_name = arm->true_state().name;
    plan.num_joints = static_cast<int32_t>(plan.joint_name.size());
    for (int64_t ahead_us = 0; ahead_us <= sim.plan_horizon_us; ahead_us += sim.plan_step_us) {
      plan.point_utime.push_back(utime + ahead_us);
      plan.position.push_back(arm->planned_reported_positions(ahead_us * 1e-6));
    }
    plan.num_points = static_cast<int32_t>(plan.point_utime.size());
    node.safety().publish(settings.channels.planned_trajectory, &plan);
  };
  node.add_timer(period_us, [&] {
    const int64_t now_us = monotonic_us();
    const bool allowed =
        status_allows && status_arrival_us >= 0 && now_us - status_arrival_us <= sim.status_deadline_us;
    arm->step((now_us - last_step_us) * 1e-6, allowed);
    last_step_us = now_us;
    const int64_t utime = wall_utime();
    const joint_state_t reported = to_message(arm->reported_state(), settings.robot.id, utime);
    const joint_state_t truth = to_message(arm->true_state(), settings.robot.id, utime);
    // The plan goes first: a replanned arm (halted, resumed, encoder jump)
    // is never seen off its old plan.
    if (sim.publish_plan && (now_us >= next_plan_us || allowed != planned_allowed ||
                             arm->offsets_version() != planned_offsets_version)) {
      publish_plan(utime);
      next_plan_us = now_us + plan_period_us;
      planned_allowed = allowed;
      planned_offsets_version = arm->offsets_version();
    }
    node.safety().publish(settings.channels.joint_state, &reported);
    node.safety().publish(settings.channels.sim_true_joint_state, &truth);
    node.counters().frames_out++;
    node.heartbeat().set_status(allowed ? "moving" : "halted: no permission to move");
  });
  node.run();
  return 0;
}

}  // namespace tofguard::sim
