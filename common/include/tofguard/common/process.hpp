#pragma once
// What a tofguard-<name> process is, for --help and its messages. Each
// component says it (e.g. risk::process_info()); the one process runner
// (deployment/process_runner.hpp) parses the command line with it.
#include <string>
#include <vector>

namespace tofguard {

struct ProcessInfo {
  // e.g. "tofguard-renderer"
  std::string name;
  // One paragraph: what the process does, its channels in and out.
  std::string summary;
  // Tools that only need LCM (e.g. tofguard-reset) may run without --config:
  // they then get the default wire settings (LCM_DEFAULT_URL, default
  // channel names).
  bool config_required = true;
  // Tools with options of their own (tofguard-reset --who ...) get the
  // arguments besides --config; for every other process an argument besides
  // --config is a usage error (exit code 2).
  bool takes_arguments = false;
  // A process of one camera (tofguard-camera, -renderer, -discrepancy,
  // -estimator, ...): `--camera ID` selects which of the config's cameras
  // it serves (required when the config has several); it then works on that
  // camera's channels under that camera's name (deployment::select_camera).
  bool per_camera = false;
};

// The names of the processes of one camera (those whose ProcessInfo has
// per_camera): a deployment of several cameras runs one of each per camera,
// named with the camera's suffix ("tofguard-renderer/tof-side").
const std::vector<std::string>& per_camera_process_names();

}  // namespace tofguard
