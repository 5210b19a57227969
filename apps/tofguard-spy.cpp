// tofguard-spy: watch the live tofguard channels in a terminal (spy_process.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/spy/spy_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, spy::process_info(),
      [](const deployment::Config& config, const std::vector<std::string>& arguments) {
        return spy::run_spy(config.lcm, arguments);
      });
}
