// tofguard-launch CONFIG: starts, supervises and stops the process group of
// the deployment config (launch_process.hpp).
#include <string>
#include <vector>

#include "tofguard/common/config_error.hpp"
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/launch/launch_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  // `tofguard-launch CONFIG` is the same as `tofguard-launch --config CONFIG`.
  std::vector<char*> args(argv, argv + argc);
  std::string config_flag = "--config";
  if (argc >= 2 && argv[1][0] != '-') args.insert(args.begin() + 1, config_flag.data());
  return deployment::run_process(static_cast<int>(args.size()), args.data(), launch::process_info(),
                                 [](const deployment::Config& config, const std::vector<std::string>& rest) {
                                   launch::LaunchProcessSettings settings =
                                       deployment::launch_process_settings(config);
                                   if (rest.size() == 2 && rest[0] == "--host" && !rest[1].empty()) {
                                     settings.host = rest[1];
                                   } else if (!rest.empty()) {
                                     throw ConfigError("unexpected argument '" + rest[0] +
                                                       "' (usage: tofguard-launch CONFIG [--host NAME])");
                                   }
                                   return launch::run_launch(settings);
                                 });
}
