// The second camera's processes on a second computer: the embedded
// default's deployment with two cameras (two_camera_config.hpp) split over
// two hosts joined by a cable (second_host.hpp: two network namespaces and
// a veth pair). The second host runs the side camera's tofguard-camera,
// -renderer, -discrepancy and -estimator and the arm's controller
// (tofguard-joints-sim), started by its own tofguard-launch --host side-pc
// from the launch section of the same config; this host the mast camera's
// and the judgement (tofguard-risk, tofguard-intervene). LCM crosses the cable (udpm,
// ttl=1): the side camera's discrepancy, depth images and heartbeats this
// way, the joint states that way, and the signed status and speed limit the
// arm's controller verifies. Both hosts read one clock here; on two
// computers their clocks must agree within what docs/architecture.md,
// "Several computers", sets.
#include <gtest/gtest.h>

#include <csignal>

#include <iostream>
#include <map>
#include <string>

#include "live_chain.hpp"
#include "second_host.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/risk_t.hpp"
#include "two_camera_config.hpp"

namespace tofguard::test {
namespace {

// The processes the second host runs (the side camera's and the arm's
// controller), as its launcher names them (no '/': a name is a log file's).
const std::vector<std::pair<std::string, std::string>>& second_host_processes() {
  static const std::vector<std::pair<std::string, std::string>> processes = {
      {"tofguard-camera/tof-side", "side-camera"},
      {"tofguard-renderer/tof-side", "side-renderer"},
      {"tofguard-discrepancy/tof-side", "side-discrepancy"},
      {"tofguard-estimator/tof-side", "side-estimator"},
      {"tofguard-joints-sim", "joints-sim"}};
  return processes;
}

// The launch section's entries for the second host (host: side-pc).
std::string second_host_launch_section() {
  std::string entries;
  for (const auto& [process, name] : second_host_processes()) {
    const auto slash = process.find('/');
    const std::string binary = process.substr(0, slash);
    const std::string camera = slash == std::string::npos ? "" : ", --camera, " + process.substr(slash + 1);
    const bool required = binary != "tofguard-estimator";
    entries += "    - {name: " + name + ", command: [" + binary + ", --config, \"{config}\"" + camera +
               "], required: " + (required ? "true" : "false") + ", host: side-pc}\n";
  }
  return "launch:\n  processes:\n" + entries +
         "  restart_backoff_initial_ms: 200\n  restart_backoff_max_ms: 5000\n  max_restarts: 5\n"
         "  restart_window_s: 60\n  log_dir: " +
         output_dir() +
         "/two-hosts-logs\n  recorder: {enabled: true, max_file_mb: 50, max_total_mb: 500, max_age_h: 24}\n";
}

// The two-camera deployment with both LCM URLs routed beyond the host
// (ttl=1): over the cable and no farther; its launch section starts the
// second host's processes there.
std::string two_host_config() {
  return two_camera_config("two-hosts", {{"7667?ttl=0", "7667?ttl=1"}, {"7668?ttl=0", "7668?ttl=1"}},
                           second_host_launch_section());
}

TEST(TwoHosts, TheSecondCamerasProcessesOnASecondComputerJudgedHere) {
  SecondHost second_host;
  LiveChain chain("two-hosts", LiveChain::ConfigFile{two_host_config()}, false);
  // The second host: its own launcher, from the same config.
  std::vector<std::string> launch_argv = second_host.argv_prefix();
  launch_argv.insert(launch_argv.end(),
                     {bin_dir() + "/tofguard-launch", chain.config_path(), "--host", "side-pc"});
  Subprocess second_launcher("two-hosts-launch-side-pc", launch_argv);
  // This host: the rest.
  for (const std::string& p : chain_processes_of(chain.config())) {
    bool there = false;
    for (const auto& [process, name] : second_host_processes()) there = there || process == p;
    if (!there) chain.start(p);
  }
  std::map<std::string, int64_t> verdicts_by_camera;
  chain.on_frame_verdict = [&](const risk_t& r) { ++verdicts_by_camera[verdict_camera(r)]; };

  chain.bring_to_motion("start of the test");
  if (HasFatalFailure()) return;
  {
    SCOPED_TRACE("nominal motion over two hosts");
    const int64_t start_us = monotonic_us();
    const int stops_before = chain.stops_seen();
    verdicts_by_camera.clear();
    chain.wait([&] { return monotonic_us() - start_us > 10'000'000; }, std::chrono::seconds(11));
    std::cout << "10 s over two hosts: " << chain.stops_seen() - stops_before << " stops, "
              << verdicts_by_camera["tof-mast"] << " verdicts of tof-mast, " << verdicts_by_camera["tof-side"]
              << " of tof-side (judged on this host from the second host's discrepancy)" << std::endl;
    EXPECT_EQ(chain.stops_seen(), stops_before)
        << chain.last_status().reason << second_launcher.stdout_text();
    EXPECT_GE(verdicts_by_camera["tof-side"], 200);
    EXPECT_GE(verdicts_by_camera["tof-mast"], 200);
    // The second host's processes are heard here.
    for (const char* process : {"tofguard-camera/tof-side", "tofguard-renderer/tof-side",
                                "tofguard-discrepancy/tof-side", "tofguard-joints-sim"}) {
      EXPECT_EQ(chain.heartbeats().count(process), 1u) << process;
    }
  }
  {
    // The cable pulled: the side camera's frames and the joint states stop
    // arriving here, the signed status stops arriving there. Stopped within
    // the joint state's and the camera's deadlines and the chain's 200 ms.
    SCOPED_TRACE("the cable pulled");
    ASSERT_TRUE(chain.motion_allowed());
    const int64_t pulled_us = monotonic_us();
    second_host.link(false);
    ASSERT_TRUE(chain.wait([&] { return chain.first_stop_since(pulled_us) >= 0; }, std::chrono::seconds(3)))
        << chain.describe_last_risk();
    const int64_t stop_ms = (chain.first_stop_since(pulled_us) - pulled_us) / 1000;
    std::cout << "cable pulled: stopped " << stop_ms << " ms later: " << chain.last_status().reason
              << std::endl;
    EXPECT_LE(stop_ms * 1000, chain.config().risk.depth_deadline_us + 200'000);
    EXPECT_TRUE(chain.last_risk().cause == risk_t::CAUSE_SENSOR_FAULT ||
                chain.last_risk().cause == risk_t::CAUSE_COMPONENT_FAULT)
        << chain.describe_last_risk();
    second_host.link(true);
    chain.bring_to_motion("the cable plugged back");
  }
  second_launcher.signal(SIGINT);
  EXPECT_EQ(second_launcher.wait(std::chrono::seconds(10)), 0) << second_launcher.stdout_text();
}

}  // namespace
}  // namespace tofguard::test
