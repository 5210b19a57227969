// tofguard-calibrate-extrinsics: the camera's pose from an LCM log of the arm
// moving with known joint angles (calibrate_extrinsics_tool.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/estimator/calibrate_extrinsics_tool.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, estimator::calibrate_extrinsics_info(),
      [](const deployment::Config& config, const std::vector<std::string>& arguments) {
        return estimator::run_calibrate_extrinsics(deployment::estimator_process_settings(config), arguments);
      });
}
