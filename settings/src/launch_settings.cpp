#include "tofguard/settings/launch_settings.hpp"

namespace tofguard::settings {

LaunchSettings read_launch_settings(YamlMap map) {
  LaunchSettings launch;
  for (auto& p : map.maps("processes")) {
    LaunchedProcess process;
    process.name = p.string("name");
    process.command = p.strings("command");
    if (process.command.empty()) p.fail("command", "a non-empty list: program and arguments");
    process.required = p.boolean("required");
    if (auto host = p.optional_string("host")) {
      if (host->empty()) p.fail("host", "a computer's name (absent: the main computer)", "''");
      process.host = *host;
    }
    p.finish();
    launch.processes.push_back(process);
  }
  launch.restart_backoff_initial_us = map.milliseconds_as_us("restart_backoff_initial_ms", 1, 60000);
  launch.restart_backoff_max_us = map.milliseconds_as_us("restart_backoff_max_ms", 1, 600000);
  launch.max_restarts = static_cast<int>(map.integer("max_restarts", 0, 1000));
  launch.restart_window_us = map.seconds_as_us("restart_window_s", 1, 86400);
  launch.log_dir = map.path("log_dir");
  YamlMap recorder = map.map("recorder");
  launch.recorder.enabled = recorder.boolean("enabled");
  launch.recorder.max_file_mb = recorder.number("max_file_mb", 0.1, 100000);
  launch.recorder.max_total_mb = recorder.number("max_total_mb", 0.1, 10000000);
  launch.recorder.max_age_h = recorder.number("max_age_h", 0.01, 100000);
  recorder.finish();
  map.finish();
  return launch;
}

}  // namespace tofguard::settings
