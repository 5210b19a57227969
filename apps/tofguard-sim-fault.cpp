// tofguard-sim-fault: injects faults into the running simulator
// (sim_fault_tool.hpp).
#include <optional>
#include <string>
#include <vector>

#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/sim/sim_fault_tool.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, sim::sim_fault_info(),
      [](const deployment::Config& config, const std::vector<std::string>& arguments) {
        // --camera ID: the camera a camera fault goes to; with several
        // cameras a camera fault must name it (a joint fault needs none).
        std::vector<std::string> rest;
        std::optional<std::string> camera;
        for (size_t i = 0; i < arguments.size(); ++i) {
          if (arguments[i] == "--camera" && i + 1 < arguments.size()) {
            camera = arguments[++i];
          } else {
            rest.push_back(arguments[i]);
          }
        }
        sim::SimFaultToolSettings settings =
            deployment::sim_fault_tool_settings(camera ? deployment::select_camera(config, *camera) : config);
        if (!camera && config.cameras.size() > 1) settings.camera_id.clear();
        return sim::run_sim_fault(settings, rest);
      });
}
