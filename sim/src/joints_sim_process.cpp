#include "tofguard/sim/joints_sim_process.hpp"

#include <cmath>
#include <functional>
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
#include "tofguard/sim/speed_limit_follower.hpp"
#include "tofguard/sim_controller_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"
#include "tofguard/speed_limit_t.hpp"

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

// The process's LCM side: the permission to move and the encoder faults
// in, the simulated arm stepped at joints_sim.rate_hz, its reported and true
// joint states and its plan out.
class JointsSimWiring {
 public:
  JointsSimWiring(const JointsSimProcessSettings& settings, SimulatedArm* arm)
      : settings_(settings),
        sim_(settings.joints_sim),
        arm_(*arm),
        node_(settings.lcm, settings.channels, "tofguard-joints-sim"),
        plan_period_us_(static_cast<int64_t>(1e6 / sim_.plan_rate_hz)) {
    // Commissioning runs without a safety chain, so without a limit.
    if (sim_.follow_speed_limit && !settings.moves_without_permission) {
      follower_.emplace(sim_.speed_limit_margin, sim_.speed_ramp_per_s);
    }
  }

  void run() {
    subscribe_status();
    if (follower_) subscribe_speed_limit();
    subscribe_faults();
    subscribe_controller_faults();
    const int64_t period_us = static_cast<int64_t>(1e6 / sim_.rate_hz);
    last_step_us_ = monotonic_us();
    node_.add_timer(period_us, [this] { step(); });
    node_.run();
  }

 private:
  void on_status(const safety_status_t& s) {
    status_allows_ = s.motion_allowed;
    status_arrival_us_ = monotonic_us();
  }

  // `T` on `channel` as the arm's controller takes what may let it move
  // (docs/security.md): with a key only verified on `auth_channel`, the
  // plain channel not read at all; without one, the plain channel. What is
  // refused is counted and said.
  template <typename T>
  void subscribe_signed(const std::string& channel, const std::string& auth_channel,
                        std::string (*check)(const T&), std::function<void(const T&)> take) {
    if (!auth::authenticated(settings_.auth)) {
      node_.subscribe<T>(node_.safety(), channel, take, check);
      return;
    }
    if (!verifier_) verifier_.emplace(settings_.auth.key, settings_.auth.max_age_us);
    node_.subscribe<authenticated_message_t>(
        node_.safety(), auth_channel,
        [this, channel, auth_channel, check, take](const authenticated_message_t& m) {
          std::string why;
          const auto message = verifier_->open<T>(m, channel, wall_utime(), &why);
          if (message && (why = check(*message)).empty()) {
            take(*message);
            return;
          }
          node_.counters().validation_errors++;
          node_.errors().report(auth_channel, auth_channel + ": refused: " + why);
        });
  }

  void subscribe_status() {
    subscribe_signed<safety_status_t>(settings_.channels.status, settings_.channels.status_auth,
                                      check_safety_status,
                                      [this](const safety_status_t& s) { on_status(s); });
  }

  void subscribe_speed_limit() {
    subscribe_signed<speed_limit_t>(
        settings_.channels.speed_limit, settings_.channels.speed_limit_auth, check_speed_limit,
        [this](const speed_limit_t& limit) { follower_->on_limit(limit, monotonic_us()); });
  }

  void subscribe_controller_faults() {
    node_.subscribe<sim_controller_fault_t>(
        node_.safety(), settings_.channels.sim_controller_fault,
        [this](const sim_controller_fault_t& fault) {
          if (!arm_.set_drive(fault.drive_joint, fault.drive_rad_s)) {
            node_.counters().validation_errors++;
            node_.errors().report(settings_.channels.sim_controller_fault,
                                  settings_.channels.sim_controller_fault +
                                      ": drive_joint: expected a joint of the arm or nothing, got '" +
                                      fault.drive_joint + "'");
            return;
          }
          ignores_speed_limit_ = fault.ignore_speed_limit;
          std::cerr << "tofguard-joints-sim: controller fault: "
                    << (ignores_speed_limit_ ? "ignores the speed limit" : "follows the speed limit again");
          if (!fault.drive_joint.empty())
            std::cerr << ", drives " << fault.drive_joint << " at " << fault.drive_rad_s << " rad/s";
          std::cerr << std::endl;
        },
        check_sim_controller_fault);
  }

  void subscribe_faults() {
    node_.subscribe<sim_joint_fault_t>(
        node_.safety(), settings_.channels.sim_joint_fault,
        [this](const sim_joint_fault_t& fault) {
          const ChannelNames& channels = settings_.channels;
          if (!arm_.set_encoder_offset(fault.joint, fault.offset)) {
            node_.counters().validation_errors++;
            node_.errors().report(
                channels.sim_joint_fault,
                channels.sim_joint_fault + ": joint: expected a joint of the arm, got '" + fault.joint + "'");
            return;
          }
          std::cerr << "tofguard-joints-sim: encoder fault on " << fault.joint << ": offset " << fault.offset
                    << std::endl;
        },
        check_sim_joint_fault);
  }

  void publish_plan(int64_t utime) {
    planned_trajectory_t plan;
    plan.utime = utime;
    plan.joint_name = arm_.true_state().name;
    plan.num_joints = static_cast<int32_t>(plan.joint_name.size());
    for (int64_t ahead_us = 0; ahead_us <= sim_.plan_horizon_us; ahead_us += sim_.plan_step_us) {
      plan.point_utime.push_back(utime + ahead_us);
      plan.position.push_back(arm_.planned_reported_positions(ahead_us * 1e-6));
    }
    plan.num_points = static_cast<int32_t>(plan.point_utime.size());
    node_.safety().publish(settings_.channels.planned_trajectory, &plan);
  }

  // One period: the arm moves while the permission is fresh, then its
  // plan (when due), reported and true joint states go out.
  void step() {
    const int64_t now_us = monotonic_us();
    const bool allowed =
        settings_.moves_without_permission ||
        (status_allows_ && status_arrival_us_ >= 0 && now_us - status_arrival_us_ <= sim_.status_deadline_us);
    const double dt_s = (now_us - last_step_us_) * 1e-6;
    // The follower keeps learning while a controller fault ignores it.
    double scale = follower_ ? follower_->next_scale(now_us, dt_s) : 1.0;
    if (ignores_speed_limit_) scale = 1.0;
    arm_.step(dt_s, allowed, scale);
    last_step_us_ = now_us;
    const int64_t utime = wall_utime();
    if (follower_) follower_->on_joint_state(utime, allowed ? scale : 0.0);
    const joint_state_t reported = to_message(arm_.reported_state(), settings_.robot.id, utime);
    const joint_state_t truth = to_message(arm_.true_state(), settings_.robot.id, utime);
    // The plan goes first: a replanned arm (halted, resumed, encoder jump)
    // is never seen off its old plan.
    // A speed scale changed by more than kReplanScale since the last plan
    // is a new plan too (the old one runs ahead of or behind the arm).
    constexpr double kReplanScale = 0.05;
    if (sim_.publish_plan &&
        (now_us >= next_plan_us_ || allowed != planned_allowed_ ||
         arm_.plan_version() != planned_plan_version_ || std::abs(scale - planned_scale_) > kReplanScale)) {
      publish_plan(utime);
      next_plan_us_ = now_us + plan_period_us_;
      planned_allowed_ = allowed;
      planned_plan_version_ = arm_.plan_version();
      planned_scale_ = scale;
    }
    node_.safety().publish(settings_.channels.joint_state, &reported);
    node_.safety().publish(settings_.channels.sim_true_joint_state, &truth);
    node_.counters().frames_out++;
    const std::string moving =
        follower_
            ? "moving at " + std::to_string(static_cast<int>(std::lround(100 * scale))) + " % of full speed"
            : "moving";
    const std::string stage = arm_.task_stage();
    node_.heartbeat().set_status((settings_.moves_without_permission
                                      ? "moving without a permission (commissioning)"
                                  : allowed ? moving
                                            : "halted: no permission to move") +
                                 (stage.empty() ? "" : "; task: " + stage));
  }

  const JointsSimProcessSettings& settings_;
  const JointsSimSettings& sim_;
  SimulatedArm& arm_;
  LcmNode node_;
  std::optional<auth::MessageVerifier> verifier_;
  // joints_sim.follow_speed_limit: the speed scale from SAFETY_SPEED_LIMIT.
  std::optional<SpeedLimitFollower> follower_;
  double planned_scale_ = 1;
  // SIM_CONTROLLER_FAULT: full speed whatever the limit says.
  bool ignores_speed_limit_ = false;
  bool status_allows_ = false;
  int64_t status_arrival_us_ = -1;
  int64_t last_step_us_ = 0;
  // The plan: every 1/plan_rate_hz, and at once when the permission to move
  // changes (the arm halts or resumes), from the joint state just published.
  const int64_t plan_period_us_;
  int64_t next_plan_us_ = 0;
  bool planned_allowed_ = false;
  int planned_plan_version_ = 0;
};

}  // namespace

ProcessInfo joints_sim_info() {
  return {"tofguard-joints-sim",
          "The simulated arm: publishes JOINT_STATE (reported, with encoder faults) and\n"
          "SIM_TRUE_JOINT_STATE (the truth) at joints_sim.rate_hz, following the periodic\n"
          "motion of the config, and its plan on PLANNED_TRAJECTORY (joints_sim.plan);\n"
          "halts while SAFETY_STATUS withdraws permission or is stale; with\n"
          "joints_sim.follow_speed_limit, slows to SAFETY_SPEED_LIMIT.\n"
          "--task: follows joints_sim.task (the assistive task) instead of the periodic motion.\n"
          "--commissioning: moves without a permission (a commissioning recording,\n"
          "docs/camera.md); never with a safety chain in charge.\n"
          "Encoder faults: joints_sim.faults in the config, or sim_joint_fault_t on SIM_JOINT_FAULT;\n"
          "a controller that ignores the speed limit or drives a joint: sim_controller_fault_t on\n"
          "SIM_CONTROLLER_FAULT."};
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
  const auto arm = std::make_unique<SimulatedArm>(settings.joints_sim, urdf_joints, settings.config_file,
                                                  settings.follows_task);
  JointsSimWiring(settings, arm.get()).run();
  return 0;
}

}  // namespace tofguard::sim
