// tofguard-estimator as a real process over real LCM (private network
// namespace) with the real simulated camera and arm: the arm moves slowly
// about the side-reach pose; before any fault the periodic estimates find
// no joint offset; after tofguard-sim-fault makes a4 read 10 degrees more
// than it is, an estimate names a4 and about -10 degrees; a discrepancy
// past the warning level gets that frame estimated at once
// (TRIGGER_WARNING).
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <cmath>
#include <iostream>
#include <optional>

#include "tofguard/common/clock.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The embedded default with the arm moving slowly (+-1 degree) about the
// side-reach pose, where every link is in view, and a periodic estimate
// every 400 ms.
std::string rig_config() {
  return sim_config_variant("estimator-process",
                            {{"a1: {center: -0.30, amplitude: 0.35, period_s: 9.0}",
                              "a1: {center: -0.6, amplitude: 0.02, period_s: 9.0}"},
                             {"a2: {center: 0.70, amplitude: 0.20, period_s: 7.0, phase_rad: 1.0}",
                              "a2: {center: 1.3, amplitude: 0.02, period_s: 7.0, phase_rad: 1.0}"},
                             {"a3: {center: 0.00, amplitude: 0.30, period_s: 11.0}",
                              "a3: {center: -0.4, amplitude: 0.02, period_s: 11.0}"},
                             {"a4: {center: 1.10, amplitude: 0.25, period_s: 6.0, phase_rad: 2.0}",
                              "a4: {center: 1.2, amplitude: 0.02, period_s: 6.0, phase_rad: 2.0}"},
                             {"a5: {center: 0.00, amplitude: 0.40, period_s: 8.0}",
                              "a5: {center: 0.6, amplitude: 0.02, period_s: 8.0}"},
                             {"a6: {center: 0.60, amplitude: 0.25, period_s: 5.0, phase_rad: 0.5}",
                              "a6: {center: 1.0, amplitude: 0.02, period_s: 5.0, phase_rad: 0.5}"},
                             {"a7: {center: 0.00, amplitude: 0.50, period_s: 4.0}",
                              "a7: {center: -0.4, amplitude: 0.02, period_s: 4.0}"},
                             {"periodic_period_ms: 1000", "periodic_period_ms: 400"}});
}

struct Rig {
  std::string config_path = rig_config();
  deployment::Config config = deployment::load_config(config_path, nullptr);
  lcm::LCM safety{config.lcm.url};
  lcm::LCM images{config.lcm.image_url};
  std::vector<motion_estimate_t> estimates;
  std::optional<depth_image_t> newest_frame;
  std::optional<heartbeat_t> heartbeat;

  Rig() {
    safety.subscribe(config.channels.motion_estimate, &Rig::on_estimate, this);
    safety.subscribe(config.channels.heartbeat, &Rig::on_heartbeat, this);
    images.subscribe(config.channels.depth, &Rig::on_depth, this);
  }
  void on_estimate(const lcm::ReceiveBuffer*, const std::string&, const motion_estimate_t* m) {
    estimates.push_back(*m);
  }
  void on_heartbeat(const lcm::ReceiveBuffer*, const std::string&, const heartbeat_t* m) {
    if (m->process == "tofguard-estimator") heartbeat = *m;
  }
  void on_depth(const lcm::ReceiveBuffer*, const std::string&, const depth_image_t* m) { newest_frame = *m; }
  void pump() {
    safety.handleTimeout(2);
    images.handleTimeout(2);
  }
  Subprocess start(const std::string& name) {
    return Subprocess("estimator-" + name, {bin_dir() + "/" + name, "--config", config_path});
  }
};

double offset_deg(const motion_estimate_t& m, const std::string& joint) {
  for (int k = 0; k < m.num_joints; ++k) {
    if (m.joint_name[k] == joint) return (m.estimated_position[k] - m.reported_position[k]) / kDeg;
  }
  return NAN;
}

TEST(EstimatorProcess, NamesAnEncoderOffsetOnRealFrames) {
  Rig rig;
  Subprocess estimator = rig.start("tofguard-estimator");
  Subprocess arm = rig.start("tofguard-joints-sim");
  Subprocess camera = rig.start("tofguard-camera");
  auto stderr_all = [&] { return estimator.stderr_text() + arm.stderr_text() + camera.stderr_text(); };

  // Before any fault: periodic, usable, no offset of a4 beyond 3 degrees.
  ASSERT_TRUE(wait_until(
      [&] {
        for (const motion_estimate_t& m : rig.estimates) {
          if (m.usable && m.trigger == motion_estimate_t::TRIGGER_PERIODIC) return true;
        }
        return false;
      },
      std::chrono::seconds(20), [&] { rig.pump(); }))
      << stderr_all();
  // (Copies: pumping LCM grows rig.estimates.)
  std::optional<motion_estimate_t> clean;
  for (const motion_estimate_t& m : rig.estimates)
    if (m.usable) clean = m;
  ASSERT_TRUE(clean.has_value());
  EXPECT_EQ(clean->num_joints, 7);
  EXPECT_EQ(clean->camera_id, rig.config.camera.id);
  EXPECT_LT(std::abs(offset_deg(*clean, "a4")), 3.0);
  EXPECT_GT(clean->num_points, 1000);
  EXPECT_GT(clean->compute_us, 0);
  // Made of the frame and the ones just before it (no discrepancy process
  // here: no frame is known to be past the warning level).
  EXPECT_EQ(clean->num_frames, rig.config.estimator.frames_per_estimate);

  // a4 reads 10 degrees more than it is.
  ASSERT_EQ(run_command("estimator-fault", {bin_dir() + "/tofguard-sim-fault", "--config", rig.config_path,
                                            "--joint", "a4", "--offset-deg", "10"}),
            0);
  const int64_t fault_utime = wall_utime();
  std::optional<motion_estimate_t> faulty;
  ASSERT_TRUE(wait_until(
      [&] {
        for (const motion_estimate_t& m : rig.estimates) {
          // A frame captured well after the fault reached the arm.
          if (m.usable && m.utime > fault_utime + 200000) {
            faulty = m;
            return true;
          }
        }
        return false;
      },
      std::chrono::seconds(20), [&] { rig.pump(); }))
      << stderr_all();
  // The estimate sees a4 10 degrees less than it reads, and a4 is the joint
  // with the largest offset.
  std::cout << "estimate of frame " << faulty->seq << ": a4 " << offset_deg(*faulty, "a4")
            << " deg, residual " << faulty->residual_before_mm << " -> " << faulty->residual_after_mm
            << " mm, " << faulty->compute_us << " us; before the fault a4 " << offset_deg(*clean, "a4")
            << " deg\n";
  EXPECT_NEAR(offset_deg(*faulty, "a4"), -10.0, 2.5);
  for (const char* other : {"a1", "a2", "a3", "a5", "a6", "a7"}) {
    EXPECT_LT(std::abs(offset_deg(*faulty, other)), std::abs(offset_deg(*faulty, "a4"))) << other;
  }
  EXPECT_GT(faulty->residual_before_mm, faulty->residual_after_mm);

  // A discrepancy past the warning level: that frame is estimated at once.
  // The estimator estimates a frame once, and at most one warning per
  // warning.min_interval_ms of camera time: the newest frame may already be
  // the periodic schedule's (a loaded machine delivers few frames between
  // two), or a warning of the fault's own frames may have come just before.
  // Then a later frame is flagged, up to five times; one of them must be
  // estimated for its warning.
  bool warning_estimated = false;
  int64_t last_flagged_utime = 0;
  for (int attempt = 0; attempt < 5 && !warning_estimated; ++attempt) {
    ASSERT_TRUE(wait_until(
        [&] {
          return rig.newest_frame.has_value() &&
                 rig.newest_frame->utime >= last_flagged_utime + rig.config.estimator.warning_min_interval_us;
        },
        std::chrono::seconds(5), [&] { rig.pump(); }));
    discrepancy_t d{};
    d.utime = rig.newest_frame->utime;
    d.seq = rig.newest_frame->seq;
    d.camera_id = rig.config.camera.id;
    d.usable = true;
    d.mismatch_fraction = 0.5;
    d.p95_abs_dis_mm = 200;
    d.num_links = 0;
    d.num_robot_links = 0;
    last_flagged_utime = d.utime;
    rig.safety.publish(rig.config.channels.discrepancy, &d);
    wait_until(
        [&] {
          for (const motion_estimate_t& m : rig.estimates) {
            if (m.seq == d.seq && m.trigger == motion_estimate_t::TRIGGER_WARNING) warning_estimated = true;
          }
          return warning_estimated;
        },
        std::chrono::seconds(4), [&] { rig.pump(); });
  }
  EXPECT_TRUE(warning_estimated) << stderr_all();

  ASSERT_TRUE(wait_until([&] { return rig.heartbeat && rig.heartbeat->frames_out >= 3; },
                         std::chrono::seconds(2), [&] { rig.pump(); }));
  EXPECT_EQ(rig.heartbeat->decode_errors, 0);
}

}  // namespace
}  // namespace tofguard::test
