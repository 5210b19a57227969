#include "tofguard/deployment/process_runner.hpp"

#include <cstdlib>
#include <exception>
#include <iostream>
#include <optional>

#include "tofguard/common/lcm_node.hpp"

namespace tofguard::deployment {

namespace {

// A process of one camera serves the camera `--camera` names, or the only
// one; with several cameras it must be told which.
Config select_served_camera(const Config& config, const std::optional<std::string>& camera_id) {
  if (camera_id) return select_camera(config, *camera_id);
  if (config.cameras.size() == 1) return config;
  std::string ids;
  for (const CameraSection& camera : config.cameras) ids += (ids.empty() ? "" : ", ") + camera.id;
  throw ConfigError(config.file + ": cameras: " + std::to_string(config.cameras.size()) + " cameras (" + ids +
                    "); name the one this process serves with --camera ID");
}

}  // namespace

int run_process(int argc, char** argv, const ProcessInfo& info, const ProcessBody& body) {
  std::string config_path;
  std::optional<std::string> camera_id;
  std::vector<std::string> rest;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << "usage: " << info.name << (info.config_required ? " --config FILE" : " [--config FILE]")
                << (info.per_camera ? " [--camera ID]" : "") << " [options]\n\n"
                << info.summary << "\n";
      return 0;
    }
    if (arg == "--config") {
      if (i + 1 >= argc) {
        std::cerr << info.name << ": --config needs a file\n";
        return kConfigErrorExitCode;
      }
      config_path = argv[++i];
    } else if (arg == "--camera" && info.per_camera) {
      if (i + 1 >= argc) {
        std::cerr << info.name << ": --camera needs a camera id\n";
        return kConfigErrorExitCode;
      }
      camera_id = argv[++i];
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
    if (info.per_camera && !config_path.empty()) config = select_served_camera(config, camera_id);
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
