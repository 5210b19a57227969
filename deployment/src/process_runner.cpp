#include "tofguard/deployment/process_runner.hpp"

#include <cstdlib>
#include <exception>
#include <iostream>

#include "tofguard/common/lcm_node.hpp"

namespace tofguard::deployment {

int run_process(int argc, char** argv, const ProcessInfo& info, const ProcessBody& body) {
  std::string config_path;
  std::vector<std::string> rest;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << "usage: " << info.name << (info.config_required ? " --config FILE" : " [--config FILE]")
                << " [options]\n\n"
                << info.summary << "\n";
      return 0;
    }
    if (arg == "--config") {
      if (i + 1 >= argc) {
        std::cerr << info.name << ": --config needs a file\n";
        return kConfigErrorExitCode;
      }
      config_path = argv[++i];
    } else {
      rest.push_back(arg);
    }
  }
  if (config_path.empty() && info.config_required) {
    std::cerr << info.name << ": no --config FILE given (config/sim.yaml is the simulated default)\n";
    return kConfigErrorExitCode;
  }
  Config config;
  try {
    config = config_path.empty() ? default_wire_config(std::getenv("LCM_DEFAULT_URL"))
                                 : load_config(config_path, std::getenv("LCM_DEFAULT_URL"));
  } catch (const ConfigError& e) {
    std::cerr << info.name << ": config error: " << e.what() << "\n";
    return kConfigErrorExitCode;
  }
  if (!info.takes_arguments && !rest.empty()) {
    std::cerr << info.name << ": unknown argument '" << rest[0] << "'\n";
    return kConfigErrorExitCode;
  }
  for (const std::string& warning : start_warnings(config)) std::cerr << info.name << ": " << warning << "\n";
  install_stop_signal_handlers();
  try {
    return body(config, rest);
  } catch (const ConfigError& e) {
    std::cerr << info.name << ": config error: " << e.what() << "\n";
    return kConfigErrorExitCode;
  } catch (const std::exception& e) {
    std::cerr << info.name << ": " << e.what() << "\n";
    return 1;
  }
}

}  // namespace tofguard::deployment
