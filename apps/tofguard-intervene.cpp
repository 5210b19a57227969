// tofguard-intervene: SAFETY_RISK, JOINT_STATE, SAFETY_RESET -> SAFETY_STATUS,
// SAFETY_RESET_REPLY and the power-cut actuator (intervene_process.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/intervene/intervene_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, intervene::process_info(),
      [](const deployment::Config& config, const std::vector<std::string>&) {
        return intervene::run_intervene(deployment::intervene_process_settings(config));
      });
}
