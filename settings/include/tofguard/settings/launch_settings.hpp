#pragma once
// tofguard-launch's settings (config section `launch`, optional: only
// tofguard-launch needs it). Durations are integer microseconds, converted
// once when the file is read.
#include <cstdint>
#include <string>
#include <vector>

#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/yaml_reader.hpp"

namespace tofguard::settings {

// One process of the group tofguard-launch starts (launch.processes), in
// start order.
struct LaunchedProcess {
  std::string name;
  // command: argv; "{config}" in any argument becomes the config file's
  // absolute path. A bare program name is looked up beside tofguard-launch,
  // then in PATH.
  std::vector<std::string> command;
  // required: a required process that keeps crashing is reported loudly;
  // the chain is unsafe without it (the risk classifier sees its heartbeat
  // missing).
  bool required = true;
  // host (optional): the computer the process runs on, as `tofguard-launch
  // --host NAME` names it (a camera's processes on a second PC: docs/
  // architecture.md, "Several computers"); absent: the main computer, the
  // one tofguard-launch without --host runs, which also records the black
  // box.
  std::string host;
};

// launch.recorder: the black-box recorder: lcm-logger on both LCM URLs into
// rotating files.
struct RecorderSettings {
  bool enabled = false;
  // max_file_mb, max_total_mb, max_age_h: a new file every max_file_mb; the
  // oldest files are deleted when all together exceed max_total_mb or are
  // older than max_age_h.
  double max_file_mb = 0;
  double max_total_mb = 0;
  double max_age_h = 0;
};

struct LaunchSettings {
  std::vector<LaunchedProcess> processes;
  // restart_backoff_initial_ms, restart_backoff_max_ms: restart back-off
  // doubles from initial to max; microseconds.
  int64_t restart_backoff_initial_us = 0;
  int64_t restart_backoff_max_us = 0;
  // max_restarts, restart_window_s: more restarts than this within the
  // window -> left stopped. Microseconds.
  int max_restarts = 0;
  int64_t restart_window_us = 0;
  // log_dir: each process's stdout/stderr (<name>.log) and the recordings go
  // here; relative to the config file's folder; created when missing.
  std::string log_dir;
  RecorderSettings recorder;
};

// Reads (and finishes) the `launch` section.
LaunchSettings read_launch_settings(YamlMap section);

// Everything tofguard-launch needs.
struct LaunchProcessSettings {
  // The config file's path as given ({config} in commands becomes its
  // absolute path; messages name it).
  std::string config_file;
  // Both URLs are recorded.
  LcmSettings lcm;
  LaunchSettings launch;
  // --host NAME: this computer's processes (LaunchedProcess::host); "" the
  // main computer's.
  std::string host;
};

}  // namespace tofguard::settings

// The component's own names for its settings (tofguard::launch::LaunchedProcess, ...).
namespace tofguard::launch {
using settings::LaunchedProcess;
using settings::LaunchProcessSettings;
using settings::LaunchSettings;
using settings::read_launch_settings;
using settings::RecorderSettings;
}  // namespace tofguard::launch
