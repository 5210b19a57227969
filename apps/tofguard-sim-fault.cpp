// tofguard-sim-fault: injects faults into the running simulator
// (sim_fault_tool.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/sim/sim_fault_tool.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, sim::sim_fault_info(),
      [](const deployment::Config& config, const std::vector<std::string>& arguments) {
        return sim::run_sim_fault(deployment::sim_fault_tool_settings(config), arguments);
      });
}
