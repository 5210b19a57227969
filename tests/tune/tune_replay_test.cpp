// The target of tofguard-tune: on a nominal recording of a
// camera it has not seen, it gives thresholds that meet the false-stop
// target on a second recording of that camera.
//
// The camera (unseen_camera.hpp): noise 8 mm + 2.0 mm/m^2 r^2 along the ray
// at 25 Hz; config/sim.yaml's discrepancy.noise is 4 + 1.2 d^2. Two
// recordings of it, written in-process (nominal_log.hpp): other noise and
// another stretch of the arm's motion. tofguard-tune (the executable) tunes
// on the first; its fit is checked against the simulated truth, converted
// from the ray to depth (below); the second recording is replayed with
// lcm-logplayer into the observer chain with the tuned config (log_replay.hpp)
// and no frame may be judged DANGEROUS, the permission to move held while it
// plays.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <string>

#include "log_replay.hpp"
#include "nominal_log.hpp"
#include "tofguard/sim/tof_error_model.hpp"
#include "tool_support.hpp"
#include "unseen_camera.hpp"

namespace tofguard::test {
namespace {

// The truth in depth Z. The camera's noise is along the ray: r = Z / f with
// f = 1 / sqrt(1 + x^2 + y^2) (x, y the pixel's normalised coordinates), so
// sigma_Z = f (s0 + k r^2) = f s0 + k Z^2 / f, times |1 - p'(r)| of the
// distance calibration d - p(d) (docs/camera.md), which the config's
// polynomial makes 0.90..1.10 over 0.5..5 m. The model's a + b Z^2 is one
// curve for every pixel: the fit must lie within the band the image's rays
// span, f from the corner's (176 x 144, fx 221: 0.89) to 1, each end
// widened by the calibration's factor and 5 % for the fit's own error.
double truth_low_mm(double z_m) {
  const double f_corner = 0.89;
  return 0.90 * 0.95 *
         std::min(f_corner * kUnseenSigma0Mm + kUnseenSigmaPerM2Mm * z_m * z_m / f_corner,
                  kUnseenSigma0Mm + kUnseenSigmaPerM2Mm * z_m * z_m);
}
double truth_high_mm(double z_m) {
  const double f_corner = 0.89;
  return 1.10 * 1.05 *
         std::max(f_corner * kUnseenSigma0Mm + kUnseenSigmaPerM2Mm * z_m * z_m / f_corner,
                  kUnseenSigma0Mm + kUnseenSigmaPerM2Mm * z_m * z_m);
}

// What tune_and_replay found.
struct TunedReplay {
  std::string tool_output;  // tofguard-tune's report
  std::string lines;        // its config lines
  std::smatch noise;        // the noise line, [1] a and [2] b
  double static_bias_mm = -1;
  double fixed_pattern_sigma_mm = -1;
  int judged_frames = 0;
  int dangerous = 0;
  std::string replay_config;  // with the tuned lines
};

// A config line `key: number` of tofguard-tune's lines, at the evidence's
// indent; -1 when absent.
double evidence_line(const std::string& lines, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(lines, m, std::regex("\n    " + key + ": ([0-9.]+)\n"))) return -1;
  return std::stod(m[1]);
}

// Two recordings of the camera of `config_path` (12 s to tune on, 8 s to
// replay, +0.5 s lead-in each: other noise, another stretch of the arm's
// motion); tofguard-tune (the executable) on the first; the second replayed
// with lcm-logplayer into the observer chain with the tuned lines in the
// replay config (noise, static_bias_mm, fixed_pattern_sigma_mm).
// `text` (a config) with discrepancy.camera_profile set to `profile`.
std::string with_camera_profile(std::string text, const std::string& profile) {
  const std::string anchor = "\n  max_depth_mm: 8000\n";
  const size_t at = text.find(anchor);
  EXPECT_NE(at, std::string::npos) << "no discrepancy.max_depth_mm line to put camera_profile after";
  if (at != std::string::npos) text.insert(at + anchor.size(), "  camera_profile: " + profile + "\n");
  return text;
}

// With `profile` (not empty): the camera's commissioned profile named in
// the config tofguard-tune reads and in the replay config.
void tune_and_replay(const std::string& name, std::string config_path, TunedReplay* r,
                     const std::string& profile = "") {
  ASSERT_FALSE(in_path("lcm-logplayer").empty() || in_path("lcm-logger").empty()) << "liblcm-bin missing";
  if (!profile.empty()) {
    const std::string profiled = output_dir() + "/" + name + "-profiled.yaml";
    write_file(profiled, with_camera_profile(read_file(config_path), profile));
    config_path = profiled;
  }
  const deployment::Config config = deployment::load_config(config_path, nullptr);
  const std::string tune_log = output_dir() + "/" + name + "-1.lcmlog";
  const std::string replay_log = output_dir() + "/" + name + "-2.lcmlog";
  NominalLogOptions first;
  first.seconds = 12;
  first.noise_seed = 101;
  write_nominal_log(tune_log, config, first);
  NominalLogOptions second;
  second.seconds = 8;
  second.noise_seed = 202;
  second.motion_start_s = 37;
  write_nominal_log(replay_log, config, second);

  const std::string tuned_lines = output_dir() + "/" + name + ".lines.yaml";
  std::string out, err;
  const int code = run_command(
      "tofguard-tune",
      {bin_dir() + "/tofguard-tune", "--config", config_path, "--log", tune_log, "--out", tuned_lines}, &out,
      &err);
  std::cout << out << err << std::flush;
  r->tool_output = out;
  ASSERT_EQ(code, 0) << err;
  r->lines = read_file(tuned_lines);
  ASSERT_TRUE(std::regex_search(
      r->lines, r->noise,
      std::regex(R"(\n  noise: \{sigma_at_0m_mm: ([0-9.]+), sigma_per_m2_mm: ([0-9.]+)\}\n)")))
      << r->lines;
  r->static_bias_mm = evidence_line(r->lines, "static_bias_mm");
  r->fixed_pattern_sigma_mm = evidence_line(r->lines, "fixed_pattern_sigma_mm");
  ASSERT_GE(r->static_bias_mm, 0) << r->lines;
  ASSERT_GE(r->fixed_pattern_sigma_mm, 0) << r->lines;

  // The replay config at the camera's rate (config/sim.yaml's as
  // docs/replay.md makes it: the camera's own settings do not matter, no
  // camera runs) with the tuned lines in place of the default's commissioned
  // ones and no camera profile but the test's own. (--config
  // with this test's variant would not do: record-scenario rewrites
  // "models/" inside its absolute paths.)
  const std::string replay_config = output_dir() + "/" + name + "-replay.yaml";
  ASSERT_EQ(
      run_command("write-replay-config",
                  {"/bin/bash", source_dir() + "/scripts/record-scenario", "--write-config", replay_config,
                   "--replay", "--rate-hz", std::to_string(std::lround(config.camera.rate_hz))},
                  &out, &err),
      0)
      << out << err;
  std::string text = read_file(replay_config);
  // The line starting with `key` (config/sim.yaml's commissioned values,
  // whatever they are) replaced by `to` ("": removed).
  const auto replace_line = [&](const std::string& key, const std::string& to) {
    const std::string line = config_line(text, key);
    text.replace(text.find("\n" + line) + 1, line.size(), to);
  };
  replace_line("  noise: {sigma_at_0m_mm: ", r->noise[0].str().substr(1));
  replace_line("    static_bias_mm: ", "    static_bias_mm: " + std::to_string(r->static_bias_mm) + "\n");
  replace_line("    fixed_pattern_sigma_mm: ",
               "    fixed_pattern_sigma_mm: " + std::to_string(r->fixed_pattern_sigma_mm) + "\n");
  replace_line("    silhouette_allowance: ", "");
  replace_line("  camera_profile: ", "");
  // The recordings show no wheelchair user (unseen_camera.hpp, kNoUser).
  erase_config_section(&text, "occupant");
  if (!profile.empty()) text = with_camera_profile(text, profile);
  write_file(replay_config, text);
  r->replay_config = replay_config;
  ASSERT_EQ(deployment::load_config(replay_config, nullptr).camera.rate_hz, config.camera.rate_hz);

  const InputLog input = read_input_log(replay_log);
  const Replay replay(replay_log, name + "-replay", replay_config);
  const ReplayOutput& result = replay.output();
  expect_every_frame_judged_once(input, result);
  ASSERT_TRUE(result.reset_accepted && result.first_allowed_us() > 0) << "motion never allowed";
  const Status* stop = result.first_stop();
  if (stop) {
    EXPECT_GT(stop->received_us, result.last_input_us) << "stopped during the log: " << stop->reason;
  }
  const std::set<int64_t> judged = input.judged_seqs();
  for (const Verdict& v : result.verdicts) {
    if (!judged.count(v.seq)) continue;
    ++r->judged_frames;
    if (v.level == risk_t::DANGEROUS) {
      ++r->dangerous;
      ADD_FAILURE() << v.key() << " | " << v.detail;
    }
  }
  std::cout << "replay of the second recording with the tuned config: " << r->judged_frames
            << " frames judged, " << r->dangerous << " DANGEROUS" << std::endl;
  if (::testing::Test::HasFailure()) std::cout << describe(result) << replay.stderr_of_all() << std::flush;
}

// The frames at h of the report's run `label` ("with the fitted noise",
// "with the config's noise"); -1 when not found.
int frames_at_h(const std::string& report, const std::string& label) {
  const size_t at = report.find(label);
  if (at == std::string::npos) return -1;
  std::smatch m;
  const std::string rest = report.substr(at);
  if (!std::regex_search(rest, m, std::regex(R"(frames at h: ([0-9]+))"))) return -1;
  return std::stoi(m[1]);
}

TEST(TuneReplay, TunedOnOneRecordingTheSecondNeverStops) {
  TunedReplay r;
  tune_and_replay("tune-unseen", unseen_camera_config("tune-unseen"), &r);
  if (::testing::Test::HasFatalFailure()) return;
  const double a = std::stod(r.noise[1]), b = std::stod(r.noise[2]);
  // Against the truth where the scene has depth (the default scene: the
  // fitted bins span about 1..3 m).
  for (double z : {1.0, 1.5, 2.0, 2.5, 3.0}) {
    const double sigma = a + b * z * z;
    EXPECT_GE(sigma, truth_low_mm(z)) << "at " << z << " m: fitted " << a << " + " << b << " d^2";
    EXPECT_LE(sigma, truth_high_mm(z)) << "at " << z << " m: fitted " << a << " + " << b << " d^2";
  }
  EXPECT_NE(r.lines.find("pixels_per_sample: the config's 1 stands"), std::string::npos)
      << "independent noise per pixel: " << r.lines;
  // This camera's only static errors: the distance polynomial's residual
  // after camera.calibration (0.4 mm), whole-millimetre depths (sigma
  // 0.29 mm) and the meshes' simplification (0.1 mm).
  EXPECT_LE(r.static_bias_mm, 1.5) << r.lines;
  EXPECT_LE(r.fixed_pattern_sigma_mm, 1.0) << r.lines;
  EXPECT_EQ(r.dangerous, 0);
}

// A camera with the static errors of a real one (draw_imperfect_camera:
// wiggling, slope, fixed pattern, reflectivity bias, multipath; warmed up):
// with the config's allowance of 0 its nominal frames cross h (the camera
// reads as off); tofguard-tune measures its static error, and with the
// measured allowance the second recording never stops.
TEST(TuneReplay, AnImperfectCameraTunedOnOneRecordingTheSecondNeverStops) {
  const uint64_t seed = 7;
  const sim::SimResidualSettings truth = sim::draw_imperfect_camera(seed, 4000);
  TunedReplay r;
  tune_and_replay("tune-imperfect", imperfect_camera_config("tune-imperfect", truth), &r);
  if (::testing::Test::HasFatalFailure()) return;
  // The smooth truth over the scene's depths (about 1..3 m along the ray):
  // the measured bound must cover most of it and not exceed it by more
  // than what the amplitude bias and multipath add.
  double smooth_truth_mm = 0;
  for (double r_m = 1.0; r_m <= 3.0; r_m += 0.01) {
    smooth_truth_mm =
        std::max(smooth_truth_mm,
                 std::abs(truth.wiggle_amplitude_mm *
                              std::sin(2 * M_PI * r_m / truth.wiggle_period_m + truth.wiggle_phase_rad) +
                          truth.slope_mm_per_m * r_m));
  }
  std::cout << "truth: smooth error up to " << smooth_truth_mm << " mm over 1..3 m, fixed pattern "
            << truth.pixel_offset_sigma_mm << " mm, amplitude bias " << truth.reflectivity_bias_mm_per_decade
            << " mm/decade, multipath " << truth.multipath_max_mm << " mm; measured " << r.static_bias_mm
            << " mm and " << r.fixed_pattern_sigma_mm << " mm" << std::endl;
  EXPECT_GE(r.static_bias_mm, 0.7 * smooth_truth_mm);
  EXPECT_LE(r.static_bias_mm, smooth_truth_mm + 2 * std::abs(truth.reflectivity_bias_mm_per_decade) +
                                  truth.multipath_max_mm + 3);
  EXPECT_NEAR(r.fixed_pattern_sigma_mm, truth.pixel_offset_sigma_mm, 0.3 * truth.pixel_offset_sigma_mm + 0.5);
  EXPECT_GT(frames_at_h(r.tool_output, "with the config's noise"), 0)
      << "the config's allowance of 0 should not hold";
  EXPECT_EQ(frames_at_h(r.tool_output, "with the fitted noise"), 0);
  EXPECT_EQ(r.dangerous, 0);
}

// A recording of `config`'s camera with a fault throughout (`options`),
// replayed with `replay_config`: the first DANGEROUS verdict comes within
// the first 10 frames and names `cause`; returns its detail.
std::string expect_fault_called(const deployment::Config& config, const std::string& name,
                                const std::string& replay_config, const NominalLogOptions& options,
                                int8_t cause) {
  const std::string log = output_dir() + "/" + name + "-recorded.lcmlog";
  write_nominal_log(log, config, options);
  const InputLog input = read_input_log(log);
  const Replay replay(log, name, replay_config);
  const ReplayOutput& result = replay.output();
  const std::set<int64_t> judged = input.judged_seqs();
  int frames = 0;
  const Verdict* first = nullptr;
  for (const Verdict& v : result.verdicts) {
    if (!judged.count(v.seq)) continue;
    ++frames;
    if (v.level == risk_t::DANGEROUS) {
      first = &v;
      break;
    }
  }
  EXPECT_NE(first, nullptr) << name << ": never DANGEROUS in " << frames << " frames judged\n"
                            << describe(result) << replay.stderr_of_all();
  if (first == nullptr) return "";
  std::cout << name << ": DANGEROUS at judged frame " << frames << ": " << first->key() << " | "
            << first->detail << std::endl;
  EXPECT_LE(frames, 10) << name;
  EXPECT_EQ(risk_cause_name(first->cause), risk_cause_name(cause)) << name << ": " << first->detail;
  return first->detail;
}

// Commissioning (docs/camera.md, "Commissioning a camera") on the same
// imperfect camera: tofguard-tune --profile-out learns its profile on a
// first recording; tofguard-tune with the profile measures what is left on a
// second; the third replays with both and never stops. The profile removes
// most of the static error, so the allowance, and with it the smallest
// fault that accumulates, shrinks.
TEST(TuneReplay, ACommissionedImperfectCameraNeedsASmallAllowance) {
  const sim::SimResidualSettings truth = sim::draw_imperfect_camera(7, 4000);
  const std::string config_path = imperfect_camera_config("tune-commissioned", truth);
  const deployment::Config config = deployment::load_config(config_path, nullptr);
  const std::string learn_log = output_dir() + "/tune-commissioned-0.lcmlog";
  NominalLogOptions learn;
  learn.seconds = 12;
  learn.noise_seed = 303;
  learn.motion_start_s = 80;
  write_nominal_log(learn_log, config, learn);
  const std::string profile = output_dir() + "/tune-commissioned.profile.yaml";
  std::string out, err;
  const int code = run_command(
      "tofguard-tune",
      {bin_dir() + "/tofguard-tune", "--config", config_path, "--log", learn_log, "--profile-out", profile},
      &out, &err);
  std::cout << out << err << std::flush;
  ASSERT_EQ(code, 0) << err;
  ASSERT_NE(out.find("camera profile learned"), std::string::npos) << out;

  TunedReplay r;
  tune_and_replay("tune-commissioned", config_path, &r, profile);
  if (::testing::Test::HasFatalFailure()) return;
  std::cout << "commissioned: allowance " << r.static_bias_mm << " mm smooth, " << r.fixed_pattern_sigma_mm
            << " mm fixed pattern (uncommissioned, the test before: 33.8 and 3.3)" << std::endl;
  EXPECT_NE(r.tool_output.find("camera profile applied: " + profile), std::string::npos) << r.tool_output;
  EXPECT_LT(r.static_bias_mm, 12.0);
  EXPECT_EQ(frames_at_h(r.tool_output, "with the fitted noise"), 0);
  EXPECT_EQ(r.dangerous, 0);

  // The faults the targets name, on the commissioned camera (its replay
  // config as the nominal replay's): each stops, called by its cause. The
  // camera 2 cm along its optical axis (what a distance error looks most
  // like) and 2 cm down (optical y). (2 cm along optical x is called a
  // joint error of a1 on this noisier camera, with or without the
  // allowance: docs/detection.md.)
  NominalLogOptions camera_fault;
  camera_fault.seconds = 3;
  camera_fault.noise_seed = 404;
  camera_fault.motion_start_s = 120;
  camera_fault.camera_offset.translation() = Eigen::Vector3d(0, 0, 0.02);
  expect_fault_called(config, "tune-commissioned-camera-z-2cm", r.replay_config, camera_fault,
                      risk_t::CAUSE_CALIBRATION_ERROR);
  camera_fault.noise_seed = 405;
  camera_fault.camera_offset.translation() = Eigen::Vector3d(0, 0.02, 0);
  expect_fault_called(config, "tune-commissioned-camera-y-2cm", r.replay_config, camera_fault,
                      risk_t::CAUSE_CALIBRATION_ERROR);
  // The camera's distances drifting 15 mm after commissioning (its warm-up,
  // its temperature): not a moved camera, its own finding.
  NominalLogOptions drift;
  drift.seconds = 3;
  drift.noise_seed = 406;
  drift.motion_start_s = 130;
  drift.distance_offset_mm = 15;
  const std::string drift_detail = expect_fault_called(config, "tune-commissioned-drift-15mm",
                                                       r.replay_config, drift, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_NE(drift_detail.find("camera needs recommissioning: its distances read 1"), std::string::npos)
      << drift_detail;
  NominalLogOptions joint_fault;
  joint_fault.seconds = 3;
  joint_fault.noise_seed = 505;
  joint_fault.motion_start_s = 140;
  joint_fault.encoder_offset_rad["a4"] = 3.0 * M_PI / 180.0;
  expect_fault_called(config, "tune-commissioned-a4-3deg", r.replay_config, joint_fault,
                      risk_t::CAUSE_JOINT_ERROR);
}

}  // namespace
}  // namespace tofguard::test
