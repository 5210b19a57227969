#pragma once
// The simulated arm behind tofguard-joints-sim: every movable joint follows
// its periodic motion from the config, the arm halts (velocity 0, position
// held) whenever it has no permission to move, and encoder faults make the
// *reported* position differ from the *true* one.
//
// Units: positions in rad (m for prismatic joints), velocities in rad/s
// (m/s), times in seconds.
#include <map>
#include <string>
#include <vector>

#include "tofguard/settings/sim_settings.hpp"

namespace tofguard::sim {

struct ArmState {
  std::vector<std::string> name;
  std::vector<double> position;
  std::vector<double> velocity;
};

class SimulatedArm {
 public:
  // `urdf_joints`: the URDF's actuated joints
  // (robot_model::KinematicTree::actuated_joint_names). Throws ConfigError
  // (naming `config_file` and the joints_sim key) when the motion does not
  // cover exactly those joints or a fault names an unknown joint.
  // `task`: follow joints_sim.task's waypoints instead of the periodic
  // motion (ConfigError when the config has none, or a waypoint does not
  // give exactly the URDF's movable joints).
  SimulatedArm(const JointsSimSettings& config, const std::vector<std::string>& urdf_joints,
               const std::string& config_file, bool task = false);

  // Advances by dt_s of process time. The motion time advances only while
  // `motion_allowed`, so a halted arm resumes where it stopped, and then by
  // speed_scale * dt_s (in [0, 1]: a slowed arm follows the same path,
  // its velocities scaled alike).
  void step(double dt_s, bool motion_allowed, double speed_scale = 1.0);

  // Sets joint `joint`'s encoder offset (0 clears it); false if unknown.
  bool set_encoder_offset(const std::string& joint, double offset);
  // A controller fault: from now on, while the arm may move, joint `joint`
  // is also driven at `rad_s` (rad/s, m/s for a prismatic joint; not
  // slowed by the speed scale) from where it is, in its motion and its
  // plan. An empty `joint` ends the drive: the controller, fixed, brings
  // what the drive added back to the motion at kDriveReturnRadS times the
  // speed scale, while the arm may move. False (and nothing changed) for
  // an unknown joint.
  bool set_drive(const std::string& joint, double rad_s);
  static constexpr double kDriveReturnRadS = 0.25;

  const ArmState& true_state() const { return true_state_; }
  // The arm's plan: the reported (encoder) positions `ahead_s` seconds of
  // process time from now, assuming it keeps its current permission: the
  // periodic motion (at the current speed scale) and any drive while
  // moving, where it is while halted. What a controller following its
  // encoders plans (an encoder offset is in the plan, so a faulty encoder
  // does not make the arm "leave its plan"; a drive is its own command).
  std::vector<double> planned_reported_positions(double ahead_s) const;
  // What the encoders report: true position + offset; velocity as true.
  ArmState reported_state() const;
  double elapsed_s() const { return elapsed_s_; }
  // Counts the changes a controller replans for: its encoders jumping (an
  // encoder offset set) and a drive set or ended.
  int plan_version() const { return plan_version_; }
  bool moving() const { return moving_; }
  // Where the task stands: "at <waypoint>" while holding there, "to
  // <waypoint>" while moving to it; empty without a task.
  std::string task_stage() const;
  // One cycle of the task (every waypoint's hold and the moves between
  // them), seconds of motion time; 0 without a task.
  double task_cycle_s() const;

 private:
  void update_state(bool moving);
  // Joint i's position and its velocity at full speed at motion time t_s.
  double position_at(size_t i, double t_s) const;
  double velocity_at(size_t i, double t_s) const;
  // The task's segment at motion time t_s: from waypoint `from` to `to`
  // (the same while holding), blend in [0, 1] and d(blend)/dt.
  struct TaskPhase {
    size_t from = 0, to = 0;
    double blend = 0, blend_rate = 0;
  };
  TaskPhase task_phase(double t_s) const;
  // Joint i's speed from a drive (set_drive) or its return, while moving;
  // what drives will have added to its position dt_s of process time on.
  double drive_velocity(size_t i) const;
  double driven_after(size_t i, double dt_s) const;

  std::vector<JointMotion> motion_;  // in URDF order
  // The task (empty: the periodic motion): each waypoint's positions in
  // URDF order, its hold, and the move time between waypoints.
  std::vector<std::vector<double>> task_positions_;
  std::vector<double> task_hold_s_;
  std::vector<std::string> task_names_;
  double task_move_s_ = 0;
  std::vector<EncoderFault> scheduled_faults_;
  std::map<std::string, double> offsets_;
  // set_drive: the driven joint (URDF order; -1: none), its speed, and
  // what drives have added to each joint's position so far.
  int drive_index_ = -1;
  double drive_rad_s_ = 0;
  std::vector<double> driven_;
  double elapsed_s_ = 0;
  int plan_version_ = 0;
  double motion_time_s_ = 0;
  bool moving_ = false;
  double speed_scale_ = 1;
  ArmState true_state_;
};

}  // namespace tofguard::sim
