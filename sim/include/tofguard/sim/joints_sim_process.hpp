#pragma once
// tofguard-joints-sim: the simulated arm. Publishes JOINT_STATE (what the
// encoders report, faults included) and SIM_TRUE_JOINT_STATE (the truth, for
// the simulated camera) at joints_sim.rate_hz, and its plan on
// PLANNED_TRAJECTORY (joints_sim.plan); halts while SAFETY_STATUS withdraws
// permission or is older than joints_sim.status_deadline_ms; takes encoder
// faults from the config and from SIM_JOINT_FAULT.
#include "tofguard/common/process.hpp"
#include "tofguard/settings/sim_settings.hpp"

namespace tofguard::sim {

ProcessInfo joints_sim_info();

// Runs until SIGINT/SIGTERM. A motion that does not cover exactly the URDF's
// movable joints throws ConfigError.
int run_joints_sim(const JointsSimProcessSettings& settings);

}  // namespace tofguard::sim
