#include "tofguard/common/process.hpp"

#include <cstdlib>
#include <iostream>

#include "tofguard/common/lcm_node.hpp"

namespace tofguard {

int run_process(int argc, char** argv, const ProcessInfo& info,
                const std::function<int(const Config&, const std::vector<std::string>&)>& body) {
  std::string config_path;
  std::vector<std::string> rest;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << "usage: " << info.name << (info.config_required ? " --config FILE" : " [--config FILE]") << " [options]\n\n"
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
  if (config_path.empty() && !info.config_required) {
    install_stop_signal_handlers();
    return body(default_wire_config(std::getenv("LCM_DEFAULT_URL")), rest);
  }
  if (config_path.empty()) {
    std::cerr << info.name << ": no --config FILE given (config/sim.yaml is the simulated default)\n";
    return kConfigErrorExitCode;
  }
  Config config;
  try {
    config = load_config(config_path, std::getenv("LCM_DEFAULT_URL"));
  } catch (const ConfigError& e) {
    std::cerr << info.name << ": config error: " << e.what() << "\n";
    return kConfigErrorExitCode;
  }
  install_stop_signal_handlers();
  return body(config, rest);
}

}  // namespace tofguard
