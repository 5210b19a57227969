// Two cameras, one verdict: the embedded default's deployment watched by
// its mast camera and a second camera on the wheelchair's other side
// (two_camera_config.hpp), every process of each camera running, over real
// LCM in a private network namespace. Each camera is judged on its own
// channels by tofguard-risk and the worst verdict of the two is published
// (risk/verdict_fusion.hpp): the arm moves while both see it as modelled, a
// camera that stalls stops it within its deadline and is named, and a
// camera that is knocked is named by its id.
#include <gtest/gtest.h>

#include <iostream>
#include <map>
#include <string>

#include "live_chain.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/risk_t.hpp"
#include "two_camera_config.hpp"

namespace tofguard::test {
namespace {

// The camera a fused verdict came from: its detail's "<id>: " prefix.
std::string verdict_camera(const risk_t& r) {
  const auto colon = r.detail.find(": ");
  return colon == std::string::npos ? "" : r.detail.substr(0, colon);
}

class TwoCameras : public ::testing::Test {
 protected:
  TwoCameras() : chain_("two-cameras", LiveChain::ConfigFile{two_camera_config("two-cameras")}, true) {
    chain_.on_frame_verdict = [this](const risk_t& r) { ++verdicts_by_camera_[verdict_camera(r)]; };
    for (const deployment::CameraSection& camera : chain_.config().cameras) {
      const std::string channel = deployment::select_camera(chain_.config(), camera.id).channels.depth;
      chain_.images().subscribe(channel, &TwoCameras::on_depth, this);
    }
    chain_.on_pump = [this] {
      while (chain_.images().handleTimeout(0) > 0) {
      }
    };
  }

  // tofguard-sim-fault's camera fault in camera `camera_id`.
  void camera_fault(const std::string& camera_id, const std::vector<std::string>& fault) {
    std::vector<std::string> argv{bin_dir() + "/tofguard-sim-fault",
                                  "--config",
                                  chain_.config_path(),
                                  "--camera",
                                  camera_id,
                                  "--camera-fault"};
    argv.insert(argv.end(), fault.begin(), fault.end());
    std::string out;
    ASSERT_EQ(run_command("two-cameras-fault", argv, &out), 0) << out;
  }

  // Injects `fault` into `camera_id` while the arm moves and waits for the
  // stop; expects its verdict to name the camera (and `suspect` when not
  // empty). Returns the stop's monotonic time (-1: none).
  int64_t stop_naming(const std::string& camera_id, const std::vector<std::string>& fault,
                      const std::string& suspect) {
    EXPECT_TRUE(chain_.motion_allowed());
    const int64_t fault_us = monotonic_us();
    camera_fault(camera_id, fault);
    const bool stopped =
        chain_.wait([&] { return chain_.first_stop_since(fault_us) >= 0; }, std::chrono::seconds(5));
    EXPECT_TRUE(stopped) << "no stop; last risk " << chain_.describe_last_risk();
    if (!stopped) return -1;
    std::cout << camera_id << " " << fault.front() << ": stopped "
              << (chain_.first_stop_since(fault_us) - fault_us) / 1000
              << " ms after tofguard-sim-fault started: " << chain_.last_status().reason << std::endl;
    EXPECT_EQ(verdict_camera(chain_.last_risk()), camera_id) << chain_.describe_last_risk();
    if (!suspect.empty()) {
      EXPECT_EQ(chain_.last_risk().suspect, suspect) << chain_.describe_last_risk();
    }
    EXPECT_NE(chain_.last_status().reason.find(camera_id), std::string::npos) << chain_.last_status().reason;
    return chain_.first_stop_since(fault_us);
  }

  // A stall of `camera_id`: stopped within its depth deadline and the
  // chain's 200 ms of the last frame that arrived, named; then cleared
  // and the arm moving again.
  void expect_stall_stopped_and_named(const std::string& camera_id) {
    SCOPED_TRACE(camera_id + " stalls");
    const std::string channel = deployment::select_camera(chain_.config(), camera_id).channels.depth;
    const int64_t stop_us = stop_naming(camera_id, {"stall"}, channel);
    if (stop_us < 0) return;
    const int64_t after_last_frame_us = stop_us - last_depth_arrival_us_[channel];
    std::cout << camera_id << " stall: stop " << after_last_frame_us / 1000.0 << " ms after its last frame"
              << std::endl;
    EXPECT_LE(after_last_frame_us, chain_.config().risk.depth_deadline_us + 200'000);
    camera_fault(camera_id, {"clear"});
    chain_.bring_to_motion("the " + camera_id + " camera's stall cleared");
  }

  void on_depth(const lcm::ReceiveBuffer*, const std::string& channel) {
    last_depth_arrival_us_[channel] = monotonic_us();
  }

  LiveChain chain_;
  std::map<std::string, int64_t> verdicts_by_camera_;
  std::map<std::string, int64_t> last_depth_arrival_us_;  // monotonic, by depth channel
};

TEST_F(TwoCameras, BothJudgeTheArmAndAFailingCameraStopsItNamed) {
  chain_.bring_to_motion("start of the test");
  if (HasFatalFailure()) return;
  {
    SCOPED_TRACE("nominal motion, both cameras");
    const int64_t start_us = monotonic_us();
    const int stops_before = chain_.stops_seen();
    verdicts_by_camera_.clear();
    chain_.wait([&] { return monotonic_us() - start_us > 10'000'000; }, std::chrono::seconds(11));
    std::cout << "10 s of nominal motion: " << chain_.stops_seen() - stops_before << " stops, "
              << verdicts_by_camera_["tof-mast"] << " verdicts of tof-mast, "
              << verdicts_by_camera_["tof-side"] << " of tof-side" << std::endl;
    EXPECT_EQ(chain_.stops_seen(), stops_before) << chain_.last_status().reason;
    // 300 frames each at 30 Hz: every frame of each camera is judged and
    // published (all SAFE, so each verdict is its own camera's).
    EXPECT_GE(verdicts_by_camera_["tof-side"], 200);
    EXPECT_GE(verdicts_by_camera_["tof-mast"], 200);
    EXPECT_EQ(chain_.heartbeats().count("tofguard-renderer/tof-side"), 1u);
    EXPECT_EQ(chain_.heartbeats().count("tofguard-discrepancy/tof-side"), 1u);
    EXPECT_EQ(chain_.heartbeats().count("tofguard-camera/tof-side"), 1u);
  }
  expect_stall_stopped_and_named("tof-side");
  expect_stall_stopped_and_named("tof-mast");
  if (HasFatalFailure()) return;
  {
    // A frozen image while the arm moves: the frame rule
    // (risk.sensor.frozen_repeat_frames) on that camera's frames.
    SCOPED_TRACE("tof-side freezes");
    stop_naming("tof-side", {"frozen_image"}, "TOF_DEPTH/tof-side");
    camera_fault("tof-side", {"clear"});
    chain_.bring_to_motion("the tof-side camera unfrozen");
    if (HasFatalFailure()) return;
  }
  {
    // Knocked 2 cm along its optical x: its own pose test names it. A
    // knocked camera stays where it was knocked to (the simulator keeps
    // the drift), so the diagnosis stays open and no reset is accepted.
    SCOPED_TRACE("tof-side knocked 2 cm");
    stop_naming("tof-side", {"pose_drift", "--duration-s", "0.01", "--drift-m-per-s", "2,0,0"}, "");
    EXPECT_EQ(chain_.last_risk().cause, risk_t::CAUSE_CALIBRATION_ERROR) << chain_.describe_last_risk();
    std::string out;
    const int code = run_command("two-cameras-reset",
                                 {bin_dir() + "/tofguard-reset", "--config", chain_.config_path(), "--who",
                                  "test", "--why", "camera knocked"},
                                 &out);
    EXPECT_NE(code, 0) << "a reset was accepted while tof-side's diagnosis is open: " << out;
    std::cout << "reset while tof-side is knocked: " << out << std::endl;
  }
}

}  // namespace
}  // namespace tofguard::test
