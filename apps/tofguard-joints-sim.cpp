// tofguard-joints-sim: the simulated arm (joints_sim_process.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/sim/joints_sim_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, sim::joints_sim_info(),
      [](const deployment::Config& config, const std::vector<std::string>&) {
        return sim::run_joints_sim(deployment::joints_sim_process_settings(config));
      });
}
