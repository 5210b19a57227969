#pragma once
// tofguard-camera's simulated source.
#include "tofguard/settings/sim_settings.hpp"

namespace tofguard::sim {

// camera.source == "sim": renders the scene of the config (robot and
// environment URDFs, visual geometry, unpadded) at the simulated arm's true
// joint state from channels.sim_true_joint_state, applies the ToF error
// model and the distance calibration, and publishes at camera.rate_hz.
// Faults come from camera.sim.faults and from sim_camera_fault_t on
// channels.sim_camera_fault. A frame that cannot be made (no recent true
// joint state, render failure, stall fault) or whose slot was missed
// because the process was late is counted in frames_dropped; seq counts
// frame slots, so a lost frame leaves a gap in seq.
int run_sim_camera(const SimCameraProcessSettings& settings);

}  // namespace tofguard::sim
