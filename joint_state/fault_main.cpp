// tofguard-sim-fault --joint NAME --offset-deg DEG: injects an encoder fault
// into the running tofguard-joints-sim (simulation only): from now on the
// joint reports DEG degrees more than its true angle. --offset-deg 0 clears.
#include <cmath>
#include <lcm/lcm-cpp.hpp>

#include <iostream>

#include "tofguard/clock.hpp"
#include "tofguard/process.hpp"
#include "tofguard/sim_joint_fault_t.hpp"

namespace {

int run(const tofguard::Config& config, const std::vector<std::string>& args) {
  tofguard::sim_joint_fault_t fault;
  bool have_offset = false;
  for (size_t i = 0; i + 1 < args.size(); i += 2) {
    if (args[i] == "--joint") {
      fault.joint = args[i + 1];
    } else if (args[i] == "--offset-deg") {
      try {
        fault.offset = std::stod(args[i + 1]) * M_PI / 180.0;
        have_offset = std::isfinite(fault.offset);
      } catch (const std::exception&) {
      }
    }
  }
  if (fault.joint.empty() || !have_offset || args.size() % 2 != 0) {
    std::cerr << "usage: tofguard-sim-fault [--config FILE] --joint NAME --offset-deg DEGREES\n";
    return tofguard::kConfigErrorExitCode;
  }
  lcm::LCM lcm(config.lcm.url);
  fault.utime = tofguard::wall_utime();
  if (!lcm.good() || lcm.publish(config.channels.sim_joint_fault, &fault) != 0) {
    std::cerr << "tofguard-sim-fault: cannot publish on " << config.lcm.url << "\n";
    return 3;
  }
  std::cout << "encoder fault: " << fault.joint << " reports " << args[3] << " deg more than its true angle"
            << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return tofguard::run_process(argc, argv,
                               {"tofguard-sim-fault",
                                "Injects an encoder fault into the running tofguard-joints-sim: --joint NAME\n"
                                "--offset-deg DEGREES (0 clears it). Simulation only.",
                                /*config_required=*/false},
                               run);
}
