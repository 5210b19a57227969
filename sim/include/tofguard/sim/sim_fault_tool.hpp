#pragma once
// tofguard-sim-fault: injects faults into the running simulator (simulation
// only).
//   --joint NAME --offset-deg DEG: an encoder fault in tofguard-joints-sim:
//     from now on the joint reports DEG degrees more than its true angle
//     (--offset-deg 0 clears it).
//   --camera-fault KIND [options]: a fault in the simulated ToF camera
//     (sim_camera_fault_t on SIM_CAMERA_FAULT; KIND clear ends every fault).
#include <string>
#include <vector>

#include "tofguard/common/process.hpp"
#include "tofguard/settings/sim_settings.hpp"

namespace tofguard::sim {

// Runs with or without --config (a camera fault needs it: the camera's id).
ProcessInfo sim_fault_info();

// Exit code 0 published, 2 usage error, 3 cannot publish.
int run_sim_fault(const SimFaultToolSettings& settings, const std::vector<std::string>& arguments);

}  // namespace tofguard::sim
