// tofguard-joints-sim: the simulated arm (joints_sim_process.hpp).
#include <iostream>

#include "tofguard/common/config_error.hpp"
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/sim/joints_sim_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  ProcessInfo info = sim::joints_sim_info();
  info.takes_arguments = true;
  return deployment::run_process(
      argc, argv, info, [](const deployment::Config& config, const std::vector<std::string>& arguments) {
        sim::JointsSimProcessSettings settings = deployment::joints_sim_process_settings(config);
        for (const std::string& a : arguments) {
          if (a == "--commissioning") {
            settings.moves_without_permission = true;
          } else if (a == "--task") {
            settings.follows_task = true;
          } else {
            std::cerr << "tofguard-joints-sim: unknown argument '" << a
                      << "' (expected --commissioning or --task)\n";
            return kConfigErrorExitCode;
          }
        }
        return sim::run_joints_sim(settings);
      });
}
