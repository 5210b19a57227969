#include "tofguard/launch/launch_process.hpp"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>

#include "tofguard/common/clock.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/launch/log_rotation.hpp"
#include "tofguard/launch/process_group.hpp"
#include "tofguard/launch/recordings_keeper.hpp"

namespace tofguard::launch {
namespace {

void say(const std::string& line) { std::cout << "tofguard-launch: " << line << std::endl; }

std::string own_dir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

// Every process of launch.processes, "{config}" in their commands replaced
// by `config_path` and the program resolved (beside tofguard-launch, else
// in PATH). Throws ConfigError for a program that is not found.
std::vector<ProcessSpec> process_specs(const LaunchProcessSettings& settings,
                                       const std::string& config_path) {
  const LaunchSettings& launch = settings.launch;
  std::vector<ProcessSpec> specs;
  for (size_t i = 0; i < launch.processes.size(); ++i) {
    const LaunchedProcess& p = launch.processes[i];
    if (p.host != settings.host) continue;
    ProcessSpec spec;
    spec.name = p.name;
    spec.required = p.required;
    spec.log_path = launch.log_dir + "/" + p.name + ".log";
    for (std::string arg : p.command) {
      for (size_t at = arg.find("{config}"); at != std::string::npos; at = arg.find("{config}")) {
        arg.replace(at, 8, config_path);
      }
      spec.argv.push_back(arg);
    }
    const std::string program = resolve_program(spec.argv[0], own_dir());
    if (program.empty()) {
      throw ConfigError(settings.config_file + ": launch.processes[" + std::to_string(i) +
                        "].command: expected an executable program, '" + spec.argv[0] +
                        "' is not beside tofguard-launch (" + own_dir() + ") nor in PATH");
    }
    spec.argv[0] = program;
    specs.push_back(spec);
  }
  if (specs.empty()) {
    throw ConfigError(settings.config_file + ": launch.processes: expected a process for " +
                      (settings.host.empty() ? std::string("the main computer (no host key)")
                                             : "host '" + settings.host + "' (--host)") +
                      ", got none");
  }
  return specs;
}

// The black box: an lcm-logger per LCM network, recording into
// `recordings`; never required, so a full disk or a crashed logger never
// stops the safety chain. A new file every max_file_mb. False when
// lcm-logger is not installed.
bool add_recorders(const LaunchProcessSettings& settings, const std::string& recordings,
                   std::vector<ProcessSpec>* specs) {
  const LaunchSettings& launch = settings.launch;
  std::error_code ec;
  std::filesystem::create_directories(recordings, ec);
  const std::string logger = resolve_program("lcm-logger", "");
  if (logger.empty()) return false;
  const std::string split = std::to_string(launch.recorder.max_file_mb);
  for (const auto& [which, url] : {std::pair<std::string, std::string>{"safety", settings.lcm.url},
                                   std::pair<std::string, std::string>{"images", settings.lcm.image_url}}) {
    ProcessSpec spec;
    spec.name = "recorder-" + which;
    spec.required = false;
    spec.log_path = launch.log_dir + "/" + spec.name + ".log";
    spec.argv = {logger,
                 "--lcm-url=" + url,
                 "-q",
                 "-i",
                 "--split-mb=" + split,
                 "-s",
                 recordings + "/" + which + "-%Y%m%d-%H%M%S.lcmlog"};
    specs->push_back(spec);
  }
  return true;
}

RestartPolicy restart_policy(const LaunchSettings& launch) {
  RestartPolicy policy;
  policy.initial_delay_us = launch.restart_backoff_initial_us;
  policy.max_delay_us = launch.restart_backoff_max_us;
  policy.max_restarts = launch.max_restarts;
  policy.window_us = launch.restart_window_us;
  return policy;
}

}  // namespace

ProcessInfo process_info() {
  ProcessInfo info{"tofguard-launch",
                   "Starts the process group of the deployment config (launch.processes, in order), shows\n"
                   "each process's state, restarts crashed processes with back-off (a process that keeps\n"
                   "crashing is reported and left stopped), records every channel with lcm-logger into\n"
                   "rotating files under launch.log_dir, and stops all of them on Ctrl-C / SIGTERM.\n"
                   "With --host NAME only the processes whose `host` is NAME (a second computer of the\n"
                   "deployment; it records nothing: the main computer does).\n"
                   "Usage: tofguard-launch CONFIG [--host NAME]"};
  info.takes_arguments = true;
  return info;
}

int run_launch(const LaunchProcessSettings& settings) {
  const LaunchSettings& launch = settings.launch;
  const std::string config_path = std::filesystem::absolute(settings.config_file).string();

  // Everything is checked before anything starts.
  std::vector<ProcessSpec> specs = process_specs(settings, config_path);
  std::error_code ec;
  std::filesystem::create_directories(launch.log_dir, ec);
  if (ec) {
    throw ConfigError(settings.config_file + ": launch.log_dir: expected a folder that can be created, " +
                      launch.log_dir + ": " + ec.message());
  }
  const std::string recordings = launch.log_dir + "/recordings";
  // The black box records on the main computer, which hears every channel.
  if (launch.recorder.enabled && settings.host.empty() && !add_recorders(settings, recordings, &specs)) {
    std::cerr << "tofguard-launch: lcm-logger not found in PATH (liblcm-bin): run scripts/install-deps\n";
    return kConfigErrorExitCode;
  }

  ProcessGroup group(specs, restart_policy(launch), say);
  say("starting " + std::to_string(specs.size()) + " processes from " + settings.config_file + "; logs in " +
      launch.log_dir);
  group.start_all(monotonic_us());
  std::cout << group.status_table() << std::flush;

  RecordingsKeeper keeper(launch.recorder, recordings, say);
  while (!stop_requested()) {
    const int64_t now_us = monotonic_us();
    group.poll(now_us);
    if (launch.recorder.enabled) {
      keeper.check_space(now_us);
      keeper.prune(now_us);
    }
    usleep(20000);  // the supervision period: a crash is noticed within 20 ms
  }
  say("stopping every process");
  group.stop_all(3000);
  std::cout << group.status_table() << std::flush;
  say("all processes stopped");
  return 0;
}

}  // namespace tofguard::launch
