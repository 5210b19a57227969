// Every tofguard process validates the whole config at start: a config error
// is one line on stderr naming the file and the key, exit code 2, and
// nothing is published before it. Runs in a private network namespace with a
// listener on both of the config's LCM URLs.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <csignal>

#include "tofguard/common/process.hpp"
#include "tool_support.hpp"
#include "two_camera_config.hpp"

namespace tofguard::test {
namespace {

const char* const kProcesses[] = {"tofguard-camera",      "tofguard-joints-sim", "tofguard-renderer",
                                  "tofguard-discrepancy", "tofguard-risk",       "tofguard-intervene"};

struct Counter {
  int messages = 0;
  void on_message(const lcm::ReceiveBuffer*, const std::string&) { ++messages; }
};

std::string bad_config() {
  return sim_config_variant("process-bad-config", {{"rate_hz: 30", "rate_hz: -5"}});
}

TEST(ProcessConfig, EveryProcessRejectsABadConfigWithExitCode2AndPublishesNothing) {
  const std::string path = bad_config();
  lcm::LCM safety("udpm://239.255.76.67:7667?ttl=0");
  lcm::LCM images("udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4194304");
  ASSERT_TRUE(safety.good());
  ASSERT_TRUE(images.good());
  Counter counter;
  safety.subscribe(".*", &Counter::on_message, &counter);
  images.subscribe(".*", &Counter::on_message, &counter);

  for (const char* process : kProcesses) {
    std::string out, err;
    const int code = run_command(std::string("config-") + process,
                                 {bin_dir() + "/" + process, "--config", path}, &out, &err);
    EXPECT_EQ(code, 2) << process << ": " << err;
    // Exactly one line, naming the process, the file, the key and the range.
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << process << ": " << err;
    EXPECT_NE(err.find(process), std::string::npos) << err;
    EXPECT_NE(err.find(path), std::string::npos) << err;
    EXPECT_NE(err.find("camera.rate_hz"), std::string::npos) << err;
    EXPECT_NE(err.find("expected a number in [0.1, 1000]"), std::string::npos) << err;
  }
  // Drain whatever might have been sent: nothing may have been.
  while (safety.handleTimeout(50) > 0 || images.handleTimeout(0) > 0) {
  }
  EXPECT_EQ(counter.messages, 0);
}

// A config that runs without authentication, or opens the bus beyond the
// host, is said so loudly at every process's start (docs/security.md).
TEST(ProcessConfig, EveryProcessWarnsLoudlyOfAnInsecureConfigAndAnOpenBus) {
  const std::string path = sim_config_variant(
      "process-insecure", {{"  key_file: auth.key\n", "  insecure: true\n"}, {"?ttl=0\"\n", "?ttl=1\"\n"}});
  for (const char* process : kProcesses) {
    Subprocess p(std::string("insecure-") + process, {bin_dir() + "/" + process, "--config", path});
    ASSERT_TRUE(wait_until([&] { return p.stderr_text().find("ttl=1") != std::string::npos || !p.running(); },
                           std::chrono::seconds(10)))
        << process;
    const std::string err = p.stderr_text();
    EXPECT_NE(err.find(std::string(process) + ": WARNING: auth.insecure is true: nothing is authenticated"),
              std::string::npos)
        << err;
    EXPECT_NE(err.find(std::string(process) + ": WARNING: LCM bus udpm://239.255.76.67:7667?ttl=1"),
              std::string::npos)
        << err;
    p.signal(SIGTERM);
    p.wait(std::chrono::seconds(10));
  }
}

TEST(ProcessConfig, MissingConfigArgumentIsAUsageError) {
  for (const char* process : kProcesses) {
    std::string out, err;
    EXPECT_EQ(run_command(std::string("noconfig-") + process, {bin_dir() + "/" + process}, &out, &err), 2)
        << process;
    EXPECT_NE(err.find("--config"), std::string::npos) << err;
  }
}

TEST(ProcessConfig, HelpExitsZero) {
  for (const char* process : kProcesses) {
    std::string out, err;
    EXPECT_EQ(run_command(std::string("help-") + process, {bin_dir() + "/" + process, "--help"}, &out, &err),
              0);
    EXPECT_NE(out.find(std::string("usage: ") + process), std::string::npos) << out;
  }
}

// With several cameras a process of one camera must be told which it
// serves (--camera ID); the others take no --camera. Which are which is
// per_camera_process_names(), the list tofguard-risk and the launch tests
// expand per camera: each process's --help says the same.
TEST(ProcessConfig, AProcessOfOneCameraMustBeToldWhichCamera) {
  const std::string path = two_camera_config("process-two-cameras");
  const std::vector<std::string>& per_camera = per_camera_process_names();
  for (const std::string& process : per_camera) {
    std::string out, err;
    ASSERT_EQ(run_command("help-" + process, {bin_dir() + "/" + process, "--help"}, &out, &err), 0) << err;
    EXPECT_NE(out.find("[--camera ID]"), std::string::npos) << process << ": " << out;
  }
  for (const char* process : kProcesses) {
    SCOPED_TRACE(process);
    const bool of_a_camera = std::find(per_camera.begin(), per_camera.end(), process) != per_camera.end();
    std::string out, err;
    ASSERT_EQ(run_command(std::string("help-") + process, {bin_dir() + "/" + process, "--help"}, &out, &err),
              0);
    EXPECT_EQ(out.find("[--camera ID]") != std::string::npos, of_a_camera) << out;
    if (!of_a_camera) continue;
    const int code = run_command(std::string("no-camera-") + process,
                                 {bin_dir() + "/" + process, "--config", path}, &out, &err);
    EXPECT_EQ(code, 2) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_NE(err.find("2 cameras (tof-mast, tof-side); name the one this process serves with --camera ID"),
              std::string::npos)
        << err;
    const int unknown =
        run_command(std::string("unknown-camera-") + process,
                    {bin_dir() + "/" + process, "--config", path, "--camera", "tof-roof"}, &out, &err);
    EXPECT_EQ(unknown, 2) << err;
    EXPECT_NE(err.find("no camera 'tof-roof'"), std::string::npos) << err;
  }
}

}  // namespace
}  // namespace tofguard::test
