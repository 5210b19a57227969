#include "tofguard/launch/launch_process.hpp"

#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>

#include "tofguard/common/clock.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/launch/log_rotation.hpp"
#include "tofguard/launch/process_group.hpp"

namespace tofguard::launch {
namespace {

void say(const std::string& line) { std::cout << "tofguard-launch: " << line << std::endl; }

std::string own_dir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

// Bytes free for an unprivileged writer on the filesystem of `dir`, or -1
// when it cannot be read.
int64_t free_bytes(const std::string& dir) {
  struct statvfs fs {};
  if (statvfs(dir.c_str(), &fs) != 0) return -1;
  return static_cast<int64_t>(fs.f_bavail) * static_cast<int64_t>(fs.f_frsize);
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

// Watches the recordings' disk space and prunes them to the recorder's
// size and age limits.
class RecordingsKeeper {
 public:
  RecordingsKeeper(const RecorderSettings& recorder, std::string recordings)
      : recorder_(recorder), recordings_(std::move(recordings)) {}

  // A full disk loses the black box (lcm-logger cannot write; it is not
  // required, so the safety chain goes on): say so once when it happens,
  // once when space is back, checked every second. "Full": less than one
  // recording file's worth (max_file_mb) or 1 MB free, whichever is less.
  void check_space(int64_t now_us) {
    if (now_us < next_space_check_us_) return;
    next_space_check_us_ = now_us + 1'000'000;
    const int64_t free = free_bytes(recordings_);
    const int64_t low = std::min<int64_t>(1'000'000, static_cast<int64_t>(recorder_.max_file_mb * 1e6));
    if (free >= 0 && free < low && !disk_full_) {
      disk_full_ = true;
      say("recorder: ERROR: disk full at " + recordings_ + " (" + std::to_string(free) +
          " bytes free): black-box recordings are being lost; the safety chain is not affected");
    } else if (free >= low && disk_full_) {
      disk_full_ = false;
      say("recorder: disk space back at " + recordings_ + " (" + std::to_string(free) +
          " bytes free): recording again");
    }
  }

  // Every 5 s, deletes the oldest recordings beyond the size and age limits.
  void prune(int64_t now_us) {
    if (now_us < next_prune_us_) return;
    next_prune_us_ = now_us + 5'000'000;
    const auto doomed =
        files_to_delete(list_log_files(recordings_), static_cast<uint64_t>(recorder_.max_total_mb * 1e6),
                        static_cast<int64_t>(recorder_.max_age_h * 3600), wall_utime() / 1'000'000);
    for (const auto& path : doomed) {
      std::error_code ec;
      std::filesystem::remove(path, ec);
      say("recorder: deleted " + path + " (size or age limit)");
    }
  }

 private:
  const RecorderSettings& recorder_;
  std::string recordings_;
  int64_t next_prune_us_ = 0;
  int64_t next_space_check_us_ = 0;
  bool disk_full_ = false;
};

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
  return {"tofguard-launch",
          "Starts the process group of the deployment config (launch.processes, in order), shows\n"
          "each process's state, restarts crashed processes with back-off (a process that keeps\n"
          "crashing is reported and left stopped), records every channel with lcm-logger into\n"
          "rotating files under launch.log_dir, and stops all of them on Ctrl-C / SIGTERM.\n"
          "Usage: tofguard-launch CONFIG"};
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
  if (launch.recorder.enabled && !add_recorders(settings, recordings, &specs)) {
    std::cerr << "tofguard-launch: lcm-logger not found in PATH (liblcm-bin): run scripts/install-deps\n";
    return kConfigErrorExitCode;
  }

  ProcessGroup group(specs, restart_policy(launch), say);
  say("starting " + std::to_string(specs.size()) + " processes from " + settings.config_file + "; logs in " +
      launch.log_dir);
  group.start_all(monotonic_us());
  std::cout << group.status_table() << std::flush;

  RecordingsKeeper keeper(launch.recorder, recordings);
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
