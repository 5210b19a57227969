// tofguard-reset --who NAME --why TEXT: asks tofguard-intervene to release a
// latched stop (reset_tool.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/intervene/reset_tool.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, intervene::reset_info(),
      [](const deployment::Config& config, const std::vector<std::string>& arguments) {
        return intervene::run_reset(deployment::reset_tool_settings(config), arguments);
      });
}
