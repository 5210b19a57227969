// tofguard-tune: the camera's noise model from a nominal recording
// (tune_tool.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/tune/tune_tool.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, tune::tune_info(),
      [](const deployment::Config& config, const std::vector<std::string>& arguments) {
        tune::TuneSettings settings;
        settings.renderer = deployment::renderer_process_settings(config);
        settings.discrepancy = config.discrepancy;
        settings.risk = config.risk;
        return tune::run_tune(settings, arguments);
      });
}
