// The deployment config: the embedded default loads, and every kind of
// mistake gives one line naming the file, the key and what was expected.
#include <gtest/gtest.h>
#include <sched.h>

#include <sys/stat.h>

#include <algorithm>
#include <map>
#include <string>

#include "occupant_test_config.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tool_support.hpp"
#include "two_camera_config.hpp"

namespace tofguard::test {
namespace {

std::string sim_yaml_path() { return source_dir() + "/config/sim.yaml"; }

// config/sim.yaml's silhouette allowance (its lines), as the variants below
// replace it.
std::string sim_silhouette_allowance() {
  return config_line(read_file(sim_yaml_path()), "    silhouette_allowance: {");
}

// sim.yaml with `from` replaced by `to` (which must occur), in the test
// output folder.
std::string sim_variant(const std::string& name, const std::string& from, const std::string& to) {
  return sim_config_variant("config-" + name, {{from, to}});
}

std::string config_error(const std::string& path) {
  try {
    deployment::load_config(path, nullptr);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Config, EmbeddedDefaultLoads) {
  const deployment::Config config = deployment::load_config(sim_yaml_path(), nullptr);
  EXPECT_EQ(config.robot.id, "friend-sim");
  EXPECT_EQ(config.camera.source, "sim");
  EXPECT_EQ(config.camera.intrinsics.width, 176);
  EXPECT_EQ(config.camera.intrinsics.height, 144);
  EXPECT_DOUBLE_EQ(config.camera.intrinsics.fx, 221.0);
  EXPECT_DOUBLE_EQ(config.camera.intrinsics.cy, 71.8);
  EXPECT_EQ(config.camera.pose.frame_id, "world");
  EXPECT_NEAR(config.camera.pose.rotation.norm(), 1.0, 1e-6);
  // The optical axis (z) looks forward (+x), 8 degrees to the right (-y)
  // and 35 degrees below the horizon; image right (x) is level.
  const Eigen::Vector3d optical_axis = config.camera.pose.rotation * Eigen::Vector3d::UnitZ();
  const double pitch = 35 * M_PI / 180, yaw = -8 * M_PI / 180;
  EXPECT_NEAR(optical_axis.x(), std::cos(pitch) * std::cos(yaw), 1e-6);
  EXPECT_NEAR(optical_axis.y(), std::cos(pitch) * std::sin(yaw), 1e-6);
  EXPECT_NEAR(optical_axis.z(), -std::sin(pitch), 1e-6);
  EXPECT_NEAR((config.camera.pose.rotation * Eigen::Vector3d::UnitX()).z(), 0.0, 1e-6);
  EXPECT_EQ(config.lcm.url, "udpm://239.255.76.67:7667?ttl=0");
  EXPECT_EQ(config.lcm.image_url, "udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(config.channels.depth, "TOF_DEPTH");
  EXPECT_EQ(config.channels.status, "SAFETY_STATUS");
  EXPECT_EQ(config.robot.urdf_path, source_dir() + "/config/models/friend_arm.urdf");
  ASSERT_EQ(config.environment.urdf_paths.size(), 1u);
  EXPECT_EQ(config.renderer.max_extrapolation_us, 20000);
  EXPECT_FALSE(config.camera.sim.pan_tilt_enabled);
  EXPECT_TRUE(config.risk.estimate_enabled);
  EXPECT_EQ(config.risk.estimate_wait_us, 0);
  EXPECT_TRUE(config.risk.plan_enabled);
  EXPECT_EQ(config.risk.unseen_arm_max_fraction, 0.5);
  EXPECT_TRUE(config.joints_sim.publish_plan);
  EXPECT_TRUE(config.renderer.prediction_enabled);
  EXPECT_EQ(config.renderer.camera_pose_max_extrapolation_us, 40000);
}

// The embedded default's deadlines fit together (config/sim.yaml,
// intervention.risk_deadline_ms): tofguard-risk names a stalled camera or
// discrepancy (its deadline + its check + 10 ms) before tofguard-intervene
// sees the verdicts stop, and a silent tofguard-risk still stops the arm
// within 200 ms (the deadline + one status tick + 10 ms).
TEST(Config, TheRiskMonitorNamesAStalledInputBeforeTheInterveneSeesItSilent) {
  const deployment::Config config = deployment::load_config(sim_yaml_path(), nullptr);
  const int64_t inputs_us = std::max(config.risk.depth_deadline_us, config.risk.discrepancy_deadline_us);
  EXPECT_GE(config.intervene.risk_deadline_us, inputs_us + config.risk.check_period_us + 10'000);
  const auto tick_us = static_cast<int64_t>(1e6 / config.intervene.publish_rate_hz);
  EXPECT_LE(config.intervene.risk_deadline_us + tick_us + 10'000, 200'000);
}

// Durations are read once, rounded to the nearest microsecond: what the
// renderer's state history and risk's deadlines compare.
TEST(Config, MillisecondsAreRoundedToWholeMicrosecondsOnce) {
  const std::string path = sim_config_variant(
      "config-fractional-ms", {{"  max_extrapolation_ms: 20\n", "  max_extrapolation_ms: 12.3456\n"},
                               {"camera_pose: {history_ms: 2000, max_extrapolation_ms: 40,",
                                "camera_pose: {history_ms: 2000, max_extrapolation_ms: 40.0004,"},
                               {"deadlines_ms: {depth: 150,", "deadlines_ms: {depth: 33.3334,"}});
  const deployment::Config config = deployment::load_config(path, nullptr);
  EXPECT_EQ(config.renderer.max_extrapolation_us, 12'346);
  EXPECT_EQ(config.renderer.camera_pose_max_extrapolation_us, 40'000);
  EXPECT_EQ(config.risk.depth_deadline_us, 33'333);
}

TEST(Config, LcmUrlComesFromConfigThenEnvironmentThenHostLocalDefault) {
  EXPECT_EQ(resolve_lcm_url("udpm://239.1.1.1:7000", "udpm://239.2.2.2:7000"), "udpm://239.1.1.1:7000");
  EXPECT_EQ(resolve_lcm_url("", "udpm://239.2.2.2:7000"), "udpm://239.2.2.2:7000");
  EXPECT_EQ(resolve_lcm_url("", nullptr), "udpm://239.255.76.67:7667?ttl=0");
  EXPECT_EQ(resolve_lcm_url("", ""), "udpm://239.255.76.67:7667?ttl=0");

  const std::string path = sim_variant("no-lcm-section", "  url: \"udpm://239.255.76.67:7667?ttl=0\"\n", "");
  // With lcm.url removed, LCM_DEFAULT_URL decides; the image URL names its
  // own port with a big receive buffer.
  const deployment::Config config = deployment::load_config(path, "udpm://239.9.9.9:9000?ttl=1");
  EXPECT_EQ(config.lcm.url, "udpm://239.9.9.9:9000?ttl=1");
}

TEST(Config, ImageUrlIsDerivedOnTheNextPortWithABigBuffer) {
  EXPECT_EQ(derive_image_url("udpm://239.255.76.67:7667?ttl=0"),
            "udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(derive_image_url("udpm://239.255.76.67:7667"), "udpm://239.255.76.67:7668?recv_buf_size=4194304");
  EXPECT_EQ(derive_image_url("udpm://239.1.2.3:100?recv_buf_size=100"),
            "udpm://239.1.2.3:101?recv_buf_size=100");
  EXPECT_EQ(derive_image_url("memq://"), "memq://");
}

struct BadConfig {
  std::string name;
  std::string from;
  std::string to;
  // Every one of these must appear in the one-line message.
  std::vector<std::string> expected;
};

class ConfigErrors : public ::testing::TestWithParam<BadConfig> {};

TEST_P(ConfigErrors, NameFileKeyAndExpectation) {
  const BadConfig& bad = GetParam();
  const std::string path = sim_variant(bad.name, bad.from, bad.to);
  const std::string message = config_error(path);
  EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
  EXPECT_NE(message.find(path), std::string::npos) << message;
  for (const auto& part : bad.expected) {
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' missing from: " << message;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Mistakes, ConfigErrors,
    ::testing::Values(
        BadConfig{"missing-key", "  id: friend-sim\n", "", {"robot.id", "missing key", "expected a string"}},
        BadConfig{"unknown-key",
                  "  rate_hz: 30\n",
                  "  rate_hz: 30\n  exposure_us: 300\n",
                  {"camera.exposure_us", "unknown key", "expected one of", "rate_hz"}},
        BadConfig{"unknown-section",
                  "renderer:\n",
                  "rendering:\n  x: 1\nrenderer:\n",
                  {"rendering", "unknown key"}},
        BadConfig{"wrong-type",
                  "rate_hz: 30",
                  "rate_hz: fast",
                  {"camera.rate_hz", "expected a number in", "'fast'"}},
        BadConfig{"wrong-type-int",
                  "width: 176",
                  "width: 176.5",
                  {"camera.intrinsics.width", "expected an integer", "'176.5'"}},
        BadConfig{"out-of-range",
                  "far_m: 8.0",
                  "far_m: 0.05",
                  {"renderer.far_m", "expected a distance greater than near_m"}},
        BadConfig{"bad-choice",
                  "source: sim",
                  "source: kinect",
                  {"camera.source", "expected one of sim, uvc", "'kinect'"}},
        BadConfig{"missing-path",
                  "models/friend_arm.urdf",
                  "models/no_such_arm.urdf",
                  {"robot.urdf", "expected an existing file", "no_such_arm.urdf", "does not exist"}},
        BadConfig{"not-unit-quaternion",
                  "[0.302934347, -0.581931466",
                  "[0.6, -0.581931466",
                  {"camera.pose.rotation_wxyz", "expected a unit quaternion"}},
        BadConfig{"short-list",
                  "translation_m: [-0.90, -0.20, 1.80]",
                  "translation_m: [-0.90, 1.80]",
                  {"camera.pose.translation_m", "expected a list of 3 numbers", "2 entries"}},
        BadConfig{"not-yaml", "robot:\n", "robot: [\n", {"not valid YAML"}},
        BadConfig{"pan-tilt-offset-without-head",
                  "    faults: []\n",
                  "    faults: [{kind: pan_tilt_offset, start_s: 1, duration_s: 1, pan_offset_deg: 3, "
                  "tilt_offset_deg: 0}]\n",
                  {"camera.sim.faults", "only with camera.sim.pan_tilt"}},
        BadConfig{"exposure-offset-beyond-the-period",
                  "    seed: 1\n",
                  "    seed: 1\n    exposure_offset_ms: 40\n",
                  {"camera.sim.exposure_offset_ms", "less than the frame period, 33.3", "40"}},
        BadConfig{"unseen-arm-fraction-above-1",
                  "  unseen_arm_max_fraction: 0.5\n",
                  "  unseen_arm_max_fraction: 1.5\n",
                  {"risk.unseen_arm_max_fraction", "expected a number in", "1.5"}},
        BadConfig{"unseen-arm-fraction-missing",
                  "  unseen_arm_max_fraction: 0.5\n",
                  "",
                  {"risk", "unseen_arm_max_fraction"}},
        BadConfig{"intrusion-distance-below-iso-13855",
                  "    intrusion_distance_m: 0.2\n",
                  "    intrusion_distance_m: 0.1\n",
                  {"risk.field.intrusion_distance_m", "ISO 13855", "detection capability", "got 0.1"}},
        BadConfig{"field-bin-wider-than-range",
                  "  field: {range_m: 2.0, bin_m: 0.01}\n",
                  "  field: {range_m: 0.3, bin_m: 0.5}\n",
                  {"discrepancy.field.bin_m", "no wider than range_m"}},
        BadConfig{"worker-threads-neither-a-count-nor-auto",
                  "  worker_threads: auto\n",
                  "  worker_threads: many\n",
                  {"discrepancy.worker_threads", "expected an integer in [1, 64] or auto", "'many'"}},
        BadConfig{"silhouette-allowance-without-band",
                  sim_silhouette_allowance(),
                  "    silhouette_allowance: {bias_mm: 2.3}\n",
                  {"discrepancy.evidence.silhouette_allowance.band_px", "missing key"}},
        BadConfig{"silhouette-allowance-by-link-not-a-number",
                  sim_silhouette_allowance(),
                  "    silhouette_allowance: {band_px: 11, bias_mm: 2.3, by_link: {link7: wide}}\n",
                  {"discrepancy.evidence.silhouette_allowance.by_link.link7", "'wide'"}},
        BadConfig{"silhouette-allowance-step-zero",
                  sim_silhouette_allowance(),
                  "    silhouette_allowance: {band_px: 11, step_mm: 0, bias_mm: 2.3}\n",
                  {"discrepancy.evidence.silhouette_allowance.step_mm", "'0'"}},
        BadConfig{"worker-threads-zero",
                  "  worker_threads: auto\n",
                  "  worker_threads: 0\n",
                  {"discrepancy.worker_threads", "expected an integer in [1, 64] or auto", "'0'"}},
        BadConfig{"estimate-wait-out-of-range",
                  "    wait_ms: 0\n",
                  "    wait_ms: 5000\n",
                  {"risk.estimate.wait_ms", "expected a number in"}},
        BadConfig{"serial-pulse-without-its-settings",
                  "  power_cut: lcm\n",
                  "  power_cut: serial_pulse\n",
                  {"intervention.serial_pulse", "device, line and frequency_hz"}},
        BadConfig{"serial-pulse-bad-line",
                  "  power_cut: lcm\n",
                  "  power_cut: serial_pulse\n  serial_pulse: {device: /dev/ttyUSB0, line: cts, "
                  "frequency_hz: 25}\n",
                  {"intervention.serial_pulse.line", "expected one of dtr, rts, tx", "'cts'"}},
        // auth (docs/security.md): no section, no key, a key that is not
        // there, both a key and insecure, a zero replay window.
        BadConfig{"auth-section-missing",
                  "\nauth:\n",
                  "\nnot_auth:\n",
                  {"auth", "no auth section", "insecure: true"}},
        BadConfig{"auth-key-file-missing",
                  "  key_file: auth.key\n",
                  "",
                  {"auth.key_file", "a key file made by tofguard-keygen"}},
        BadConfig{"auth-key-file-absent",
                  "key_file: auth.key",
                  "key_file: /nonexistent/auth.key",
                  {"auth.key_file", "/nonexistent/auth.key: no such key file", "tofguard-keygen"}},
        BadConfig{"auth-insecure-beside-a-key",
                  "  max_age_ms: 250\n",
                  "  max_age_ms: 250\n  insecure: true\n",
                  {"auth.key_file", "one or the other"}},
        BadConfig{"auth-zero-replay-window", "max_age_ms: 250", "max_age_ms: 0", {"auth.max_age_ms"}},
        BadConfig{"large-joint-offset-not-above-the-first",
                  "large_joint_offset_deg: 10.0",
                  "large_joint_offset_deg: 3.0",
                  {"risk.evidence.large_joint_offset_deg", "a number above joint_offset_deg"}},
        BadConfig{"large-joint-offset-m-not-above-the-first",
                  "large_joint_offset_m: 0.01",
                  "large_joint_offset_m: 0.002",
                  {"risk.evidence.large_joint_offset_m", "a number above joint_offset_m"}},
        BadConfig{"plan-step-longer-than-horizon",
                  "step_ms: 20}",
                  "step_ms: 600}",
                  {"joints_sim.plan.step_ms", "no longer than horizon_ms"}}),
    [](const ::testing::TestParamInfo<BadConfig>& info) {
      std::string name = info.param.name;
      for (auto& c : name)
        if (c == '-') c = '_';
      return name;
    });

TEST(Config, TheSilhouetteAllowanceTakesEachLinksOwnBoundAndItsStep) {
  // config/sim.yaml's, over two lines as tofguard-tune's can be pasted.
  const deployment::Config sim = deployment::load_config(sim_yaml_path(), nullptr);
  EXPECT_EQ(sim.discrepancy.evidence_silhouette_bias_mm, 6.2);
  EXPECT_EQ(sim.discrepancy.evidence_silhouette_band_px, 12);
  EXPECT_EQ(sim.discrepancy.evidence_silhouette_band_step_mm, 10.0);
  EXPECT_EQ(sim.discrepancy.evidence_silhouette_bias_by_link_mm.size(), 9u);
  EXPECT_EQ(sim.discrepancy.evidence_silhouette_bias_by_link_mm.at("link7"), 5.2);
  EXPECT_EQ(sim.discrepancy.evidence_silhouette_bias_by_link_mm.at("link2"), 0.5);
  const std::string path = sim_variant("silhouette-by-link", sim_silhouette_allowance(),
                                       "    silhouette_allowance: {band_px: 11, bias_mm: 2.3, by_link: "
                                       "{link1: 2.3, link7: 0.4}}\n");
  const deployment::Config config = deployment::load_config(path, nullptr);
  EXPECT_EQ(config.discrepancy.evidence_silhouette_bias_mm, 2.3);
  const std::map<std::string, double> expected = {{"link1", 2.3}, {"link7", 0.4}};
  EXPECT_EQ(config.discrepancy.evidence_silhouette_bias_by_link_mm, expected);
  // Without step_mm the band opens at the silhouette jump (0 here), as in
  // configs measured before tofguard-tune measured from 1 cm steps.
  EXPECT_EQ(config.discrepancy.evidence_silhouette_band_step_mm, 0.0);
}

TEST(Config, TheLargeOffsetTestIsConfiguredOrTenDegrees) {
  const deployment::Config sim = deployment::load_config(sim_yaml_path(), nullptr);
  EXPECT_NEAR(sim.risk.evidence_large_joint_offset_rad * 180 / M_PI, 10.0, 1e-12);
  EXPECT_EQ(sim.risk.evidence_large_joint_offset_m, 0.01);
  // A config written before the large-offset test: its defaults.
  const std::string path = sim_variant(
      "large-offset-absent", "    large_joint_offset_deg: 10.0\n    large_joint_offset_m: 0.01\n", "");
  const deployment::Config config = deployment::load_config(path, nullptr);
  EXPECT_NEAR(config.risk.evidence_large_joint_offset_rad * 180 / M_PI, settings::kDefaultLargeJointOffsetDeg,
              1e-12);
  EXPECT_EQ(config.risk.evidence_large_joint_offset_m, settings::kDefaultLargeJointOffsetM);
}

TEST(Config, AKeyFileOpenToOthersIsAConfigError) {
  const std::string key = output_dir() + "/config-open.key";
  write_file(key, std::string(64, 'a') + "\n");
  ::chmod(key.c_str(), 0644);
  const std::string path = sim_variant("auth-open-key", "key_file: auth.key", "key_file: " + key);
  const std::string message = config_error(path);
  EXPECT_NE(message.find("auth.key_file: " + key + ": key file is open to group or others (mode 0644)"),
            std::string::npos)
      << message;
  ::chmod(key.c_str(), 0600);
  EXPECT_EQ(config_error(path), "(no error)");  // the same file, owner-only: accepted
}

TEST(Config, InsecureNeedsNoKeyAndIsWarnedAbout) {
  const std::string path = sim_variant("auth-insecure", "  key_file: auth.key\n  # The replay",
                                       "  insecure: true\n  # The replay");
  const deployment::Config config = deployment::load_config(path, nullptr);
  EXPECT_TRUE(config.auth.insecure);
  const auto warnings = deployment::start_warnings(config);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].rfind("WARNING: auth.insecure is true: nothing is authenticated.", 0), 0u)
      << warnings[0];
  // The embedded default has a key and a host-local bus: nothing to say.
  EXPECT_TRUE(deployment::start_warnings(deployment::load_config(source_dir() + "/config/sim.yaml", nullptr))
                  .empty());
}

TEST(Config, ABusOpenBeyondTheHostIsWarnedAbout) {
  EXPECT_EQ(bus_exposure_warning("udpm://239.255.76.67:7667?ttl=0"), "");
  EXPECT_EQ(bus_exposure_warning("udpm://239.255.76.67:7667"), "");  // LCM's default ttl is 0
  EXPECT_EQ(bus_exposure_warning("memq://"), "");
  EXPECT_EQ(bus_exposure_warning("tcpq://127.0.0.1:7700"), "");
  EXPECT_NE(
      bus_exposure_warning("udpm://239.255.76.67:7667?ttl=1").find("ttl=1: its multicast leaves this host"),
      std::string::npos);
  EXPECT_NE(bus_exposure_warning("udpm://239.255.76.67:7668?recv_buf_size=4194304&ttl=3").find("ttl=3"),
            std::string::npos);
  EXPECT_NE(bus_exposure_warning("tcpq://10.0.0.2:7700").find("reaches another host"), std::string::npos);
  const std::string path = sim_variant("open-bus", "?ttl=0\"\n", "?ttl=1\"\n");
  const auto warnings = deployment::start_warnings(deployment::load_config(path, nullptr));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("WARNING: LCM bus udpm://239.255.76.67:7667?ttl=1"), std::string::npos);
}

// worker_threads: auto is read for the CPUs of the process reading it
// (what taskset or systemd's CPUAffinity left it), at most 8; a number
// stands as written.
TEST(Config, AutoWorkerThreadsFollowTheCpusTheReaderMayRunOn) {
  cpu_set_t before;
  ASSERT_EQ(sched_getaffinity(0, sizeof(before), &before), 0);
  const int cpus = CPU_COUNT(&before);
  EXPECT_EQ(deployment::load_config(sim_yaml_path(), nullptr).discrepancy.worker_threads, std::min(cpus, 8));
  // On one CPU: 1 (no worker thread).
  cpu_set_t one;
  CPU_ZERO(&one);
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &before)) {
      CPU_SET(cpu, &one);
      break;
    }
  }
  ASSERT_EQ(sched_setaffinity(0, sizeof(one), &one), 0);
  const int on_one_cpu = deployment::load_config(sim_yaml_path(), nullptr).discrepancy.worker_threads;
  ASSERT_EQ(sched_setaffinity(0, sizeof(before), &before), 0);
  EXPECT_EQ(on_one_cpu, 1);
  const std::string fixed =
      sim_variant("worker-threads-3", "  worker_threads: auto\n", "  worker_threads: 3\n");
  EXPECT_EQ(deployment::load_config(fixed, nullptr).discrepancy.worker_threads, 3);
}

TEST(Config, MissingFileIsNamed) {
  const std::string message = config_error("/nonexistent/tofguard.yaml");
  EXPECT_NE(message.find("/nonexistent/tofguard.yaml"), std::string::npos) << message;
  EXPECT_NE(message.find("no such file"), std::string::npos) << message;
}

// The occupant: absent in the embedded default (nobody modelled); given, it
// is read whole, and every mistake in it is one line naming the key.
TEST(Config, TheOccupantSectionIsOptionalAndReadWhole) {
  EXPECT_FALSE(deployment::load_config(sim_config_variant("config-no-occupant", {}, "occupant: ~\n"), nullptr)
                   .occupant.has_value());
  // The embedded default seats its user as occupant_section() does.
  const deployment::Config config = deployment::load_config(sim_yaml_path(), nullptr);
  ASSERT_TRUE(config.occupant.has_value());
  const OccupantSettings& o = *config.occupant;
  EXPECT_EQ(o.seated_on, "wheelchair");
  EXPECT_DOUBLE_EQ(o.payload_kg, 0.5);
  EXPECT_DOUBLE_EQ(o.contact_force_factor, 1.0);
  ASSERT_EQ(o.regions.size(), static_cast<size_t>(kNumBodyRegions));
  EXPECT_DOUBLE_EQ(o.regions.at(BodyRegion::kFace).envelope_m, 0.05);
  EXPECT_DOUBLE_EQ(o.regions.at(BodyRegion::kFace).clearance_m.value_or(-1), 0.03);
  EXPECT_FALSE(o.regions.at(BodyRegion::kHand).clearance_m.has_value());
  EXPECT_EQ(o.presence_min_modelled_pixels, 200);
  EXPECT_DOUBLE_EQ(o.presence_max_missing_fraction, 0.5);
  const deployment::Config same =
      deployment::load_config(sim_config_variant("config-occupant", {}, occupant_section()), nullptr);
  ASSERT_TRUE(same.occupant.has_value());
  for (const auto& [region, r] : o.regions) {
    EXPECT_DOUBLE_EQ(same.occupant->regions.at(region).envelope_m, r.envelope_m) << body_region_name(region);
    EXPECT_EQ(same.occupant->regions.at(region).clearance_m, r.clearance_m) << body_region_name(region);
  }
}

TEST(Config, OccupantMistakesNameTheKey) {
  struct Mistake {
    std::string name, from, to;
    std::vector<std::string> expected;
  };
  const std::vector<Mistake> mistakes = {
      {"face-without-clearance",
       "face: {envelope_m: 0.05, clearance_m: 0.03}",
       "face: {envelope_m: 0.05}",
       {"occupant.regions.face.clearance_m", "the head and the neck get a clearance, never a contact"}},
      {"unknown-region",
       "    thigh: {envelope_m: 0.03}\n",
       "    thigh: {envelope_m: 0.03}\n    tail: {envelope_m: 0.03}\n",
       {"occupant.regions.tail", "a body region (one of skull_and_forehead"}},
      {"missing-region",
       "    hand: {envelope_m: 0.10}\n",
       "",
       {"occupant.regions.hand", "every body region with its envelope_m"}},
      {"force-factor",
       "contact_force_factor: 1.0",
       "contact_force_factor: 3",
       {"occupant.contact_force_factor"}},
  };
  for (const Mistake& m : mistakes) {
    std::string section = occupant_section();
    const auto at = section.find(m.from);
    ASSERT_NE(at, std::string::npos) << m.name;
    section.replace(at, m.from.size(), m.to);
    const std::string path = sim_config_variant("config-occupant-" + m.name, {}, section);
    const std::string message = config_error(path);
    EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
    EXPECT_NE(message.find(path), std::string::npos) << message;
    for (const std::string& part : m.expected) {
      EXPECT_NE(message.find(part), std::string::npos)
          << m.name << ": '" << part << "' missing from: " << message;
    }
  }
}

// Several cameras: a `cameras` list; the first camera keeps the channel
// names a lone camera has, every other's per-camera channels and processes
// carry its id.
TEST(Config, ACamerasListGivesEachCameraItsChannelsAndProfile) {
  const deployment::Config config = deployment::load_config(two_camera_config("config-two-cameras"), nullptr);
  ASSERT_EQ(config.cameras.size(), 2u);
  EXPECT_EQ(config.cameras[0].id, "tof-mast");
  EXPECT_EQ(config.cameras[1].id, "tof-side");
  EXPECT_EQ(config.cameras[0].name_suffix, "");
  EXPECT_EQ(config.cameras[1].name_suffix, "/tof-side");
  ASSERT_TRUE(config.cameras[0].profile && config.cameras[1].profile);
  EXPECT_EQ(config.cameras[0].profile->camera_id, "tof-mast");
  EXPECT_EQ(config.cameras[1].profile->camera_id, "tof-side");
  EXPECT_NEAR(config.cameras[1].pose.translation_m.y(), 0.70, 1e-12);
  EXPECT_EQ(config.cameras[1].sim.seed, 2u);
  // Until a process selects one, the first.
  EXPECT_EQ(config.camera.id, "tof-mast");
  EXPECT_EQ(config.channels.depth, "TOF_DEPTH");

  const deployment::Config side = deployment::select_camera(config, "tof-side");
  EXPECT_EQ(side.camera.id, "tof-side");
  EXPECT_EQ(side.discrepancy.camera_profile, config.cameras[1].profile);
  EXPECT_EQ(side.channels.depth, "TOF_DEPTH/tof-side");
  EXPECT_EQ(side.channels.rendered, "TOF_RENDERED/tof-side");
  EXPECT_EQ(side.channels.labels, "TOF_LABELS/tof-side");
  EXPECT_EQ(side.channels.camera_pose, "CAMERA_POSE/tof-side");
  EXPECT_EQ(side.channels.discrepancy, "SAFETY_DISCREPANCY/tof-side");
  EXPECT_EQ(side.channels.motion_estimate, "MOTION_ESTIMATE/tof-side");
  EXPECT_EQ(side.channels.sim_camera_fault, "SIM_CAMERA_FAULT/tof-side");
  EXPECT_EQ(side.channels.camera_suffix, "/tof-side");
  // What every camera shares keeps its name.
  EXPECT_EQ(side.channels.joint_state, "JOINT_STATE");
  EXPECT_EQ(side.channels.risk, "SAFETY_RISK");
  EXPECT_EQ(side.channels.heartbeat, "SAFETY_HEARTBEAT");
  EXPECT_EQ(side.channels.speed_limit, "SAFETY_SPEED_LIMIT");

  try {
    deployment::select_camera(config, "tof-roof");
    ADD_FAILURE() << "an unknown camera was selected";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("no camera 'tof-roof'; the config has 'tof-mast', 'tof-side'"),
              std::string::npos)
        << e.what();
  }
}

// tofguard-risk judges every camera, each on its own channels and with the
// heartbeats of its own processes required.
TEST(Config, RiskJudgesEveryCameraOnItsOwnChannels) {
  const deployment::Config config =
      deployment::load_config(two_camera_config("config-two-cameras-risk"), nullptr);
  const risk::RiskProcessSettings risk = deployment::risk_process_settings(config);
  ASSERT_EQ(risk.cameras.size(), 2u);
  EXPECT_EQ(risk.cameras[0].channels.discrepancy, "SAFETY_DISCREPANCY");
  EXPECT_EQ(risk.cameras[1].channels.discrepancy, "SAFETY_DISCREPANCY/tof-side");
  EXPECT_EQ(risk.cameras[1].rate_hz, 30);
  EXPECT_EQ(risk.cameras[0].required_heartbeats,
            (std::vector<std::string>{"tofguard-camera", "tofguard-renderer", "tofguard-discrepancy"}));
  EXPECT_EQ(risk.cameras[1].required_heartbeats,
            (std::vector<std::string>{"tofguard-camera/tof-side", "tofguard-renderer/tof-side",
                                      "tofguard-discrepancy/tof-side"}));
  // A lone camera is a list of one.
  const risk::RiskProcessSettings lone =
      deployment::risk_process_settings(deployment::load_config(sim_yaml_path(), nullptr));
  ASSERT_EQ(lone.cameras.size(), 1u);
  EXPECT_EQ(lone.cameras[0].id, "tof-mast");
  EXPECT_EQ(lone.cameras[0].channels.depth, "TOF_DEPTH");
}

TEST(Config, CameraListMistakesNameTheKey) {
  const std::string sim_yaml = read_file(sim_yaml_path());
  const std::string mast_profile = source_dir() + "/config/sim-camera-profile.yaml";
  const struct {
    std::string name;
    std::vector<std::pair<std::string, std::string>> replacements;
    std::string appended;
    std::vector<std::string> expected;
  } mistakes[] = {
      {"both", {}, sim_camera_section(sim_yaml), {"camera", "either a camera section or a cameras list"}},
      {"same-id", {{"- id: tof-side\n", "- id: tof-mast\n"}}, "", {"cameras", "id", "'tof-mast' again"}},
      {"profile-in-discrepancy",
       {{"  max_depth_mm: ", "  camera_profile: " + mast_profile + "\n  max_depth_mm: "}},
       "",
       {"discrepancy.camera_profile", "each camera names its own"}},
      {"another-cameras-profile",
       {{"sim-side-camera-profile.yaml", "sim-camera-profile.yaml"}},
       "",
       {"camera_profile", "a profile of camera 'tof-side'", "tof-mast"}},
  };
  for (const auto& m : mistakes) {
    const std::string path = two_camera_config("config-cameras-" + m.name, m.replacements, m.appended);
    const std::string message = config_error(path);
    EXPECT_EQ(message.find('\n'), std::string::npos) << m.name << ": not one line: " << message;
    EXPECT_NE(message.find(path), std::string::npos) << m.name << ": " << message;
    for (const std::string& part : m.expected) {
      EXPECT_NE(message.find(part), std::string::npos)
          << m.name << ": '" << part << "' missing from: " << message;
    }
  }
}

}  // namespace
}  // namespace tofguard::test
