#pragma once
// tofguard-launch CONFIG: starts the process group of the deployment config
// (launch.processes, in order), restarts crashed processes with back-off,
// records every tofguard channel with lcm-logger into rotating files, and
// stops everything on Ctrl-C / SIGTERM.
#include "tofguard/common/process.hpp"
#include "tofguard/settings/launch_settings.hpp"

namespace tofguard::launch {

ProcessInfo process_info();

// Everything is checked before anything starts: a program that cannot be
// found or a log_dir that cannot be created throws ConfigError.
int run_launch(const LaunchProcessSettings& settings);

}  // namespace tofguard::launch
