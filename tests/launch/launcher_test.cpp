#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <regex>

#include "tofguard/launch/log_rotation.hpp"
#include "tofguard/launch/restart_policy.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

using launch::files_to_delete;
using launch::LogFileInfo;
using launch::RestartPolicy;
using launch::RestartTracker;

constexpr int64_t kMs = 1000;

TEST(RestartPolicy, BackOffDoublesUpToItsMaximumAndGivesUp) {
  RestartTracker tracker(RestartPolicy{200 * kMs, 1000 * kMs, 5, 60'000 * kMs});
  EXPECT_EQ(tracker.on_exit(0), 200 * kMs);
  EXPECT_EQ(tracker.on_exit(1000 * kMs), 400 * kMs);
  EXPECT_EQ(tracker.on_exit(2000 * kMs), 800 * kMs);
  EXPECT_EQ(tracker.on_exit(3000 * kMs), 1000 * kMs);
  EXPECT_EQ(tracker.on_exit(4000 * kMs), 1000 * kMs);
  EXPECT_EQ(tracker.on_exit(5000 * kMs), std::nullopt);  // 5 restarts within 60 s
}

TEST(RestartPolicy, OldRestartsLeaveTheWindow) {
  RestartTracker tracker(RestartPolicy{100 * kMs, 10'000 * kMs, 2, 10'000 * kMs});
  EXPECT_EQ(tracker.on_exit(0), 100 * kMs);
  EXPECT_EQ(tracker.on_exit(1000 * kMs), 200 * kMs);
  EXPECT_EQ(tracker.on_exit(2000 * kMs), std::nullopt);
  // 12 s later only the restart at 1 s... no: both left the 10 s window.
  EXPECT_EQ(tracker.on_exit(12'000 * kMs), 100 * kMs);
}

TEST(LogRotation, DeletesTooOldThenOldestUntilTheTotalFitsButNeverTheNewest) {
  const int64_t now = 1'000'000;
  std::vector<LogFileInfo> files = {
      {"c", 300, now - 10}, {"a", 300, now - 100'000}, {"b", 300, now - 50}, {"d", 300, now - 1}};
  // a is older than a day; then b goes to get from 900 to <= 700... b leaves 600.
  EXPECT_EQ(files_to_delete(files, 700, 86400, now), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(files_to_delete(files, 10'000, 86400, now), (std::vector<std::string>{"a"}));
  EXPECT_EQ(files_to_delete(files, 1, 86400, now), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_TRUE(files_to_delete({{"only", 1'000'000, 0}}, 1, 1, now).empty());
}

std::string launch_section(const std::string& log_dir, const std::string& processes, bool recorder = false) {
  return "\nlaunch:\n  processes:\n" + processes +
         "  restart_backoff_initial_ms: 50\n  restart_backoff_max_ms: 400\n  max_restarts: 3\n"
         "  restart_window_s: 60\n  log_dir: " +
         log_dir + "\n  recorder:\n    enabled: " + (recorder ? "true" : "false") +
         "\n    max_file_mb: 1\n    max_total_mb: 10\n    max_age_h: 1\n";
}

std::vector<pid_t> pids_in(const std::string& text, const std::string& name) {
  std::vector<pid_t> pids;
  const std::regex line(name + R"(: running \(pid (\d+)\))");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), line); it != std::sregex_iterator(); ++it) {
    pids.push_back(std::stoi((*it)[1].str()));
  }
  return pids;
}

// Whether any live (not zombie) process is in process group `pgid`, from
// /proc/<pid>/stat (fields: pid (comm) state ppid pgrp ...).
bool process_group_alive(pid_t pgid) {
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string stat = read_file(entry.path().string() + "/stat");
    const auto close = stat.rfind(')');
    if (close == std::string::npos) continue;
    char state = 0;
    int ppid = 0, pgrp = 0;
    if (sscanf(stat.c_str() + close + 1, " %c %d %d", &state, &ppid, &pgrp) != 3) continue;
    if (pgrp == pgid && state != 'Z') return true;
  }
  return false;
}

TEST(Launcher, MissingExecutableIsAConfigErrorBeforeAnythingStarts) {
  const std::string log_dir = output_dir() + "/launch-missing";
  std::filesystem::remove_all(log_dir);
  const std::string config = sim_config_variant(
      "launch-missing", {},
      launch_section(log_dir,
                     "    - {name: sleeper, command: [/bin/sleep, '1000'], required: true}\n"
                     "    - {name: ghost, command: [tofguard-no-such-process, --config, '{config}'], "
                     "required: true}\n"));
  std::string out, err;
  EXPECT_EQ(run_command("launch-missing", {bin_dir() + "/tofguard-launch", config}, &out, &err), 2);
  EXPECT_NE(err.find("launch.processes[1].command"), std::string::npos) << err;
  EXPECT_NE(err.find("tofguard-no-such-process"), std::string::npos) << err;
  EXPECT_NE(err.find(config), std::string::npos) << err;
  EXPECT_EQ(out.find("running"), std::string::npos) << "something started: " << out;
  EXPECT_FALSE(std::filesystem::exists(log_dir + "/sleeper.log"));
}

TEST(Launcher, RestartsAKilledProcessGivesUpOnACrashLoopAndStopsEverything) {
  const std::string log_dir = output_dir() + "/launch-group";
  std::filesystem::remove_all(log_dir);
  // `family` has a child of its own: a stop must reach it too.
  const std::string config = sim_config_variant(
      "launch-group", {},
      launch_section(log_dir,
                     "    - {name: sleeper, command: [/bin/sleep, '1000'], required: true}\n"
                     "    - {name: family, command: [/bin/bash, -c, 'sleep 1000 & wait'], required: true}\n"
                     "    - {name: crasher, command: [/bin/false], required: false}\n"));
  Subprocess launch("launch-group", {bin_dir() + "/tofguard-launch", config});
  ASSERT_TRUE(wait_until(
      [&] {
        return pids_in(launch.stdout_text(), "sleeper").size() == 1 &&
               pids_in(launch.stdout_text(), "family").size() == 1;
      },
      std::chrono::seconds(5)))
      << launch.stdout_text() << launch.stderr_text();
  const pid_t sleeper = pids_in(launch.stdout_text(), "sleeper")[0];
  const pid_t family = pids_in(launch.stdout_text(), "family")[0];

  // The crash loop: 3 restarts, then left stopped and reported.
  ASSERT_TRUE(wait_until(
      [&] {
        return launch.stdout_text().find(
                   "crasher: exited with code 1; crashed 3 times "
                   "recently: left stopped") != std::string::npos;
      },
      std::chrono::seconds(10)))
      << launch.stdout_text();

  // A required process killed: reported and restarted with a new pid.
  kill(sleeper, SIGKILL);
  ASSERT_TRUE(wait_until([&] { return pids_in(launch.stdout_text(), "sleeper").size() == 2; },
                         std::chrono::seconds(5)))
      << launch.stdout_text();
  EXPECT_NE(launch.stdout_text().find("sleeper: killed by signal 9"), std::string::npos)
      << launch.stdout_text();
  const pid_t sleeper2 = pids_in(launch.stdout_text(), "sleeper")[1];
  EXPECT_NE(sleeper2, sleeper);

  // Ctrl-C: everything gone, children of children included.
  ASSERT_TRUE(process_group_alive(sleeper2));
  ASSERT_TRUE(process_group_alive(family));
  launch.signal(SIGINT);
  EXPECT_EQ(launch.wait(std::chrono::seconds(10)), 0) << launch.stdout_text();
  EXPECT_FALSE(process_group_alive(sleeper2));
  EXPECT_FALSE(process_group_alive(family));
  EXPECT_NE(launch.stdout_text().find("all processes stopped"), std::string::npos);
}

TEST(Launcher, RecorderWritesEveryChannelToRotatingFiles) {
  const std::string log_dir = output_dir() + "/launch-recorder";
  std::filesystem::remove_all(log_dir);
  const std::string config = sim_config_variant(
      "launch-recorder", {},
      launch_section(
          log_dir,
          "    - {name: intervene, command: [tofguard-intervene, --config, '{config}'], required: true}\n",
          /*recorder=*/true));
  Subprocess launch("launch-recorder", {bin_dir() + "/tofguard-launch", config});
  // tofguard-intervene publishes SAFETY_STATUS at 50 Hz: the safety recording grows.
  auto recorded_bytes = [&] {
    uintmax_t total = 0;
    for (const auto& f : launch::list_log_files(log_dir + "/recordings")) {
      if (f.path.find("/safety-") != std::string::npos) total += f.size_bytes;
    }
    return total;
  };
  ASSERT_TRUE(wait_until([&] { return recorded_bytes() > 2000; }, std::chrono::seconds(10)))
      << launch.stdout_text() << read_file(log_dir + "/recorder-safety.log");
  launch.signal(SIGTERM);
  EXPECT_EQ(launch.wait(std::chrono::seconds(10)), 0);
}

// A second computer's processes (launch.processes[i].host): `tofguard-launch
// --host NAME` starts only those, and records nothing (the main computer
// records the black box); the main computer starts only those without a
// host.
TEST(Launcher, EachComputerStartsItsOwnProcesses) {
  const std::string log_dir = output_dir() + "/launch-hosts";
  std::filesystem::remove_all(log_dir);
  const std::string config = sim_config_variant(
      "launch-hosts", {},
      launch_section(
          log_dir,
          "    - {name: judge, command: [/bin/sleep, '1000'], required: true}\n"
          "    - {name: side-camera, command: [/bin/sleep, '1000'], required: true, host: side-pc}\n",
          /*recorder=*/true));
  Subprocess side("launch-hosts-side", {bin_dir() + "/tofguard-launch", config, "--host", "side-pc"});
  ASSERT_TRUE(wait_until([&] { return pids_in(side.stdout_text(), "side-camera").size() == 1; },
                         std::chrono::seconds(5)))
      << side.stdout_text() << side.stderr_text();
  EXPECT_NE(side.stdout_text().find("starting 1 processes"), std::string::npos) << side.stdout_text();
  EXPECT_TRUE(pids_in(side.stdout_text(), "judge").empty()) << side.stdout_text();
  EXPECT_EQ(side.stdout_text().find("recorder-"), std::string::npos) << side.stdout_text();
  side.signal(SIGINT);
  EXPECT_EQ(side.wait(std::chrono::seconds(10)), 0) << side.stdout_text();

  std::string out, err;
  EXPECT_EQ(run_command("launch-hosts-none", {bin_dir() + "/tofguard-launch", config, "--host", "roof-pc"},
                        &out, &err),
            2);
  EXPECT_NE(err.find("launch.processes: expected a process for host 'roof-pc' (--host), got none"),
            std::string::npos)
      << err;
  EXPECT_EQ(run_command("launch-hosts-bad", {bin_dir() + "/tofguard-launch", config, "--hots", "side-pc"},
                        &out, &err),
            2);
  EXPECT_NE(err.find("unexpected argument '--hots'"), std::string::npos) << err;
}

}  // namespace
}  // namespace tofguard::test
