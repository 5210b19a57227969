// tofguard-estimator: TOF_DEPTH, JOINT_STATE, CAMERA_POSE, SAFETY_DISCREPANCY,
// SAFETY_RISK -> MOTION_ESTIMATE (estimator_process.hpp, docs/estimator.md).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/estimator/estimator_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, estimator::process_info(),
      [](const deployment::Config& config, const std::vector<std::string>&) {
        return estimator::run_estimator(deployment::estimator_process_settings(config));
      });
}
