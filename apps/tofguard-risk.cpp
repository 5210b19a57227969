// tofguard-risk: SAFETY_DISCREPANCY, the inputs' arrival times, heartbeats,
// MOTION_ESTIMATE, PLANNED_TRAJECTORY -> SAFETY_RISK (risk_process.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/risk/risk_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(argc, argv, risk::process_info(),
                                 [](const deployment::Config& config, const std::vector<std::string>&) {
                                   return risk::run_risk(deployment::risk_process_settings(config));
                                 });
}
