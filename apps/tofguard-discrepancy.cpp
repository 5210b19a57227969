// tofguard-discrepancy: TOF_DEPTH, TOF_RENDERED, TOF_LABELS -> SAFETY_DISCREPANCY
// (discrepancy_process.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/discrepancy/discrepancy_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, discrepancy::process_info(),
      [](const deployment::Config& config, const std::vector<std::string>&) {
        return discrepancy::run_discrepancy(deployment::discrepancy_process_settings(config));
      });
}
