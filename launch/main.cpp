// tofguard-launch CONFIG: starts the process group of the deployment config
// (launch.processes, in order), restarts crashed processes with back-off,
// records every tofguard channel with lcm-logger into rotating files, and
// stops everything on Ctrl-C / SIGTERM.
#include <unistd.h>

#include <filesystem>
#include <iostream>

#include "tofguard/launch/log_rotation.hpp"
#include "tofguard/launch/process_group.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/process.hpp"

namespace tofguard::launch {
namespace {

void say(const std::string& line) { std::cout << "tofguard-launch: " << line << std::endl; }

std::string own_dir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

int run(const Config& config, const std::vector<std::string>& rest) {
  if (!rest.empty()) {
    std::cerr << "tofguard-launch: unknown argument '" << rest[0] << "'\n";
    return kConfigErrorExitCode;
  }
  if (!config.launch.present) {
    std::cerr << "tofguard-launch: config error: " << config.file
              << ": launch: missing key, expected a mapping with processes, restart settings, log_dir, recorder\n";
    return kConfigErrorExitCode;
  }
  const LaunchConfig& launch = config.launch;
  const std::string config_path = std::filesystem::absolute(config.file).string();

  // Everything is checked before anything starts.
  std::vector<ProcessSpec> specs;
  for (size_t i = 0; i < launch.processes.size(); ++i) {
    const LaunchedProcess& p = launch.processes[i];
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
      std::cerr << "tofguard-launch: config error: " << config.file << ": launch.processes[" << i
                << "].command: expected an executable program, '" << spec.argv[0]
                << "' is not beside tofguard-launch (" << own_dir() << ") nor in PATH\n";
      return kConfigErrorExitCode;
    }
    spec.argv[0] = program;
    specs.push_back(spec);
  }
  std::error_code ec;
  std::filesystem::create_directories(launch.log_dir, ec);
  if (ec) {
    std::cerr << "tofguard-launch: config error: " << config.file << ": launch.log_dir: expected a folder that can be "
              << "created, " << launch.log_dir << ": " << ec.message() << "\n";
    return kConfigErrorExitCode;
  }
  const std::string recordings = launch.log_dir + "/recordings";
  if (launch.recorder.enabled) {
    std::filesystem::create_directories(recordings, ec);
    const std::string logger = resolve_program("lcm-logger", "");
    if (logger.empty()) {
      std::cerr << "tofguard-launch: lcm-logger not found in PATH (liblcm-bin): run scripts/install-deps\n";
      return kConfigErrorExitCode;
    }
    // The black box: never required, so a full disk or a crashed logger
    // never stops the safety chain. A new file every max_file_mb.
    const std::string split = std::to_string(launch.recorder.max_file_mb);
    for (const auto& [which, url] : {std::pair<std::string, std::string>{"safety", config.lcm.url},
                                     std::pair<std::string, std::string>{"images", config.lcm.image_url}}) {
      ProcessSpec spec;
      spec.name = "recorder-" + which;
      spec.required = false;
      spec.log_path = launch.log_dir + "/" + spec.name + ".log";
      spec.argv = {logger, "--lcm-url=" + url, "-q", "-i", "--split-mb=" + split, "-s",
                   recordings + "/" + which + "-%Y%m%d-%H%M%S.lcmlog"};
      specs.push_back(spec);
    }
  }

  RestartPolicy policy;
  policy.initial_delay_us = static_cast<int64_t>(launch.restart_backoff_initial_ms * 1000);
  policy.max_delay_us = static_cast<int64_t>(launch.restart_backoff_max_ms * 1000);
  policy.max_restarts = launch.max_restarts;
  policy.window_us = static_cast<int64_t>(launch.restart_window_s * 1e6);
  ProcessGroup group(specs, policy, say);
  say("starting " + std::to_string(specs.size()) + " processes from " + config.file + "; logs in " +
      launch.log_dir);
  group.start_all(monotonic_us());
  std::cout << group.status_table() << std::flush;

  int64_t next_prune_us = 0;
  while (!stop_requested()) {
    const int64_t now_us = monotonic_us();
    group.poll(now_us);
    if (launch.recorder.enabled && now_us >= next_prune_us) {
      next_prune_us = now_us + 5'000'000;
      const auto doomed = files_to_delete(
          list_log_files(recordings), static_cast<uint64_t>(launch.recorder.max_total_mb * 1e6),
          static_cast<int64_t>(launch.recorder.max_age_h * 3600), wall_utime() / 1'000'000);
      for (const auto& path : doomed) {
        std::filesystem::remove(path, ec);
        say("recorder: deleted " + path + " (size or age limit)");
      }
    }
    usleep(20000);  // the supervision period: a crash is noticed within 20 ms
  }
  say("stopping every process");
  group.stop_all(3000);
  std::cout << group.status_table() << std::flush;
  say("all processes stopped");
  return 0;
}

}  // namespace
}  // namespace tofguard::launch

int main(int argc, char** argv) {
  // `tofguard-launch CONFIG` is the same as `tofguard-launch --config CONFIG`.
  std::vector<char*> args(argv, argv + argc);
  std::string config_flag = "--config";
  if (argc >= 2 && argv[1][0] != '-') args.insert(args.begin() + 1, config_flag.data());
  return tofguard::run_process(
      static_cast<int>(args.size()), args.data(),
      {"tofguard-launch",
       "Starts the process group of the deployment config (launch.processes, in order), shows\n"
       "each process's state, restarts crashed processes with back-off (a process that keeps\n"
       "crashing is reported and left stopped), records every channel with lcm-logger into\n"
       "rotating files under launch.log_dir, and stops all of them on Ctrl-C / SIGTERM.\n"
       "Usage: tofguard-launch CONFIG"},
      tofguard::launch::run);
}
