// The simulated camera's residual errors (camera.sim.residual): wiggle and
// slope, fixed-pattern noise, amplitude bias, multipath and warm-up drift,
// each checked against its formula on scenes whose truth is known; their
// config keys; and the random imperfect camera.
#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "sim_test_config.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/sim/tof_error_model.hpp"

namespace tofguard::sim {
namespace {

using sim_test::test_intrinsics;

constexpr int kWidth = 176;

// The test camera without e(r), noise, mixed or dark pixels: what it
// measures beyond the truth is the residual alone.
SimCameraSettings quiet_config() {
  SimCameraSettings c = sim_test::test_sim_config();
  c.systematic_error_m = {0.0};
  c.noise_sigma0_mm = 0;
  c.noise_sigma_per_m2_mm = 0;
  c.mixed_pixel_probability = 0;
  c.dark_pixel_probability = 0;
  return c;
}

std::vector<float> wall(float z_m) {
  const Intrinsics in = test_intrinsics();
  return std::vector<float>(static_cast<size_t>(in.width) * in.height, z_m);
}

// Measured minus true radial distance at pixel (u, v), millimetres.
double radial_error_mm(const TofImage& image, const std::vector<float>& scene, int u, int v) {
  static const camera::RadialToZ to_z(test_intrinsics());
  const size_t i = static_cast<size_t>(v) * kWidth + u;
  return (image.depth_m[i] - scene[i]) / to_z.factor(u, v) * 1e3;
}

// The mean radial error over the central 40x40 pixels, millimetres.
double central_error_mm(const TofImage& image, const std::vector<float>& scene) {
  double sum = 0;
  int count = 0;
  for (int v = 52; v < 92; ++v) {
    for (int u = 67; u < 107; ++u) {
      sum += radial_error_mm(image, scene, u, v);
      ++count;
    }
  }
  return sum / count;
}

TEST(TofResidual, WiggleAndSlopeFollowTheirFormulaOnAFlatWall) {
  SimCameraSettings config = quiet_config();
  config.residual.wiggle_amplitude_mm = 15;
  config.residual.wiggle_period_m = 2;
  config.residual.wiggle_phase_rad = 0.7;
  config.residual.slope_mm_per_m = 3;
  const TofErrorModel model(config, test_intrinsics());
  const camera::RadialToZ to_z(test_intrinsics());
  double lowest_mm = 1e9, highest_mm = -1e9;
  for (const double d : {0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0}) {
    SCOPED_TRACE("wall at " + std::to_string(d) + " m");
    const std::vector<float> scene = wall(static_cast<float>(d));
    const TofImage image = model.apply(scene, 0, 0.0);
    double sum_mm = 0, expected_sum_mm = 0;
    int count = 0;
    for (int v = 52; v < 92; ++v) {
      for (int u = 67; u < 107; ++u) {
        const double r = d / to_z.factor(u, v);
        sum_mm += radial_error_mm(image, scene, u, v);
        expected_sum_mm += 15 * std::sin(2 * M_PI * r / 2 + 0.7) + 3 * r;
        ++count;
      }
    }
    EXPECT_NEAR(sum_mm / count, expected_sum_mm / count, 0.5);
    lowest_mm = std::min(lowest_mm, sum_mm / count);
    highest_mm = std::max(highest_mm, sum_mm / count);
  }
  // The walls see most of the wiggle: a missing term would not pass.
  EXPECT_GT(highest_mm - lowest_mm, 25);
}

TEST(TofResidual, PixelOffsetsHaveTheirSigmaAndAreFixedPerCamera) {
  SimCameraSettings config = quiet_config();
  config.residual.pixel_offset_sigma_mm = 3;
  const TofErrorModel model(config, test_intrinsics());
  const std::vector<float> scene = wall(2.0f);
  const TofImage frame0 = model.apply(scene, 0, 0.0);
  double sum = 0, sum2 = 0;
  int count = 0;
  for (int v = 0; v < 144; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const double e = radial_error_mm(frame0, scene, u, v);
      ASSERT_NEAR(e, model.pixel_offset_m(u, v) * 1e3, 1e-3);
      sum += e;
      sum2 += e * e;
      ++count;
    }
  }
  const double mean = sum / count;
  EXPECT_NEAR(mean, 0.0, 0.1);  // 4 standard errors of 25344 pixels
  EXPECT_NEAR(std::sqrt(sum2 / count - mean * mean), 3.0, 0.3);
  // The same in a later frame and for a model made again from the config.
  EXPECT_EQ(frame0.depth_m, model.apply(scene, 9, 0.0).depth_m);
  EXPECT_EQ(frame0.depth_m, TofErrorModel(config, test_intrinsics()).apply(scene, 0, 0.0).depth_m);
  // Another seed, another pattern: uncorrelated with this one.
  config.seed = 2;
  const TofErrorModel other(config, test_intrinsics());
  double cross = 0;
  for (int v = 0; v < 144; ++v)
    for (int u = 0; u < kWidth; ++u) cross += model.pixel_offset_m(u, v) * other.pixel_offset_m(u, v) * 1e6;
  EXPECT_LT(std::abs(cross / count / 9.0), 0.05);
}

// The residual draws nothing per frame: with the noise on, the imperfect
// camera's frame is the ideal camera's same frame plus the fixed offsets.
TEST(TofResidual, LeavesEachFramesNoiseAsItIs) {
  SimCameraSettings config = sim_test::test_sim_config();
  config.dark_pixel_probability = 0.01;
  const TofErrorModel ideal(config, test_intrinsics());
  config.residual.pixel_offset_sigma_mm = 4;
  const TofErrorModel imperfect(config, test_intrinsics());
  const camera::RadialToZ to_z(test_intrinsics());
  const std::vector<float> scene = wall(1.5f);
  for (const uint64_t frame : {0u, 5u}) {
    const TofImage a = ideal.apply(scene, frame, 0.0);
    const TofImage b = imperfect.apply(scene, frame, 0.0);
    for (int v = 0; v < 144; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        const size_t i = static_cast<size_t>(v) * kWidth + u;
        ASSERT_EQ(a.depth_m[i] == 0.0f, b.depth_m[i] == 0.0f) << "the same invalid pixels";
        if (a.depth_m[i] == 0.0f) continue;
        const double offset_m = (b.depth_m[i] - a.depth_m[i]) / to_z.factor(u, v);
        ASSERT_NEAR(offset_m, imperfect.pixel_offset_m(u, v), 1e-6) << u << "," << v;
      }
    }
  }
}

// A surface a decade darker (amplitude.at_1m 400 instead of 4000) reads
// the configured bias per decade nearer; the bright one, at the reference
// amplitude, reads true.
TEST(TofResidual, DarkAndBrightSurfacesDifferByTheAmplitudeBias) {
  SimCameraSettings bright = quiet_config();
  bright.residual.reflectivity_bias_mm_per_decade = 3;
  bright.residual.reference_amplitude = 4000;
  SimCameraSettings dark = bright;
  dark.amplitude_at_1m = 400;
  const std::vector<float> scene = wall(1.0f);
  const double bright_mm =
      central_error_mm(TofErrorModel(bright, test_intrinsics()).apply(scene, 0, 0.0), scene);
  const double dark_mm = central_error_mm(TofErrorModel(dark, test_intrinsics()).apply(scene, 0, 0.0), scene);
  // Off-centre pixels are a little farther and oblique (amplitude up to 3 %
  // lower in the central window: 0.04 mm).
  EXPECT_NEAR(bright_mm, 0.0, 0.1);
  EXPECT_NEAR(dark_mm - bright_mm, -3.0, 0.01);
  // At 2 m the amplitude is a quarter: 3 * log10(1/4) = -1.81 mm.
  const std::vector<float> far = wall(2.0f);
  EXPECT_NEAR(central_error_mm(TofErrorModel(bright, test_intrinsics()).apply(far, 0, 0.0), far), -1.81, 0.1);
}

// A box 1 m away in front of a wall at 1.2 m: the box's pixels near its
// edge read farther (the wall lights them), by at most the maximum, which
// the box's corners reach; the box's middle and the wall read true.
TEST(TofResidual, MultipathNearAConcaveEdgeOnlyAndBounded) {
  SimCameraSettings config = quiet_config();
  config.residual.multipath_max_mm = 20;
  const TofErrorModel model(config, test_intrinsics());
  std::vector<float> scene = wall(1.2f);
  auto inside = [](int u, int v) { return u >= 60 && u < 100 && v >= 50 && v < 90; };
  for (int v = 0; v < 144; ++v)
    for (int u = 0; u < kWidth; ++u)
      if (inside(u, v)) scene[static_cast<size_t>(v) * kWidth + u] = 1.0f;
  const TofImage image = model.apply(scene, 0, 0.0);
  double largest_mm = 0;
  for (int v = 0; v < 144; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const double e = radial_error_mm(image, scene, u, v);
      largest_mm = std::max(largest_mm, e);
      ASSERT_GE(e, -1e-3) << u << "," << v;
      ASSERT_LE(e, 20 + 1e-3) << u << "," << v;
      const bool deep_inside = u >= 65 && u < 95 && v >= 55 && v < 85;
      if (!inside(u, v) || deep_inside) {
        ASSERT_NEAR(e, 0.0, 1e-3) << u << "," << v;
      }
    }
  }
  // The left edge's middle: 36 of the 80 window pixels are wall, facing
  // the box nearly head-on: 20 * 2 * 36/80 * ~0.99 = 17.8 mm; a column in,
  // 27 of 80: 13.4 mm.
  EXPECT_NEAR(radial_error_mm(image, scene, 60, 70), 17.8, 0.3);
  EXPECT_NEAR(radial_error_mm(image, scene, 61, 70), 13.4, 0.3);
  EXPECT_NEAR(largest_mm, 20.0, 1e-3);  // at the corners
  // A wall 2 m behind the box (beyond the 0.5 m range) adds nothing.
  for (float& z : scene)
    if (z > 1.1f) z = 3.0f;
  const TofImage far = model.apply(scene, 0, 0.0);
  EXPECT_NEAR(radial_error_mm(far, scene, 60, 70), 0.0, 1e-3);
}

TEST(TofResidual, WarmupDriftFollowsItsTimeConstant) {
  SimCameraSettings config = quiet_config();
  config.residual.warmup_drift_mm = 6;
  config.residual.warmup_time_constant_s = 300;
  const TofErrorModel model(config, test_intrinsics());
  const std::vector<float> scene = wall(2.0f);
  EXPECT_NEAR(central_error_mm(model.apply(scene, 0, 0.0), scene), 0.0, 1e-3);
  EXPECT_NEAR(central_error_mm(model.apply(scene, 1, 300.0), scene), 6 * (1 - std::exp(-1.0)), 1e-3);  // 3.79
  EXPECT_NEAR(central_error_mm(model.apply(scene, 2, 1200.0), scene), 6 * (1 - std::exp(-4.0)),
              1e-3);  // 5.89
  EXPECT_NEAR(model.warmup_drift_m(1200.0), 5.890e-3, 1e-6);

  // On for 900 s before the process started: its first frame has drifted
  // as the cold camera's does at 900 s, and 300 s on as at 1200 s.
  config.residual.on_before_start_s = 900;
  const TofErrorModel warm(config, test_intrinsics());
  EXPECT_NEAR(central_error_mm(warm.apply(scene, 0, 0.0), scene), 6 * (1 - std::exp(-3.0)), 1e-3);  // 5.70
  EXPECT_NEAR(warm.warmup_drift_m(300.0), 5.890e-3, 1e-6);
}

SimCameraSettings read(const std::string& residual) {
  const std::string text =
      "seed: 1\n"
      "systematic_error_m: [0.0]\n"
      "noise: {sigma0_mm: 1, sigma_per_m2_mm: 1}\n"
      "amplitude: {at_1m: 4000, min_valid: 60, dark_pixel_probability: 0}\n"
      "mixed_pixels: {jump_m: 0.05, probability: 0.5}\n" +
      residual;
  return read_sim_camera_settings(YamlMap(YAML::Load(text), "sim.yaml", ".", "camera.sim"));
}

std::string error_of(const std::string& residual) {
  try {
    read(residual);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

const std::string kResidual =
    "residual: {wiggle_amplitude_mm: 12, wiggle_period_m: 1.5, wiggle_phase_rad: -1, slope_mm_per_m: 2,\n"
    "  pixel_offset_sigma_mm: 3, reflectivity_bias_mm_per_decade: -2, reference_amplitude: 1000,\n"
    "  multipath_max_mm: 15, warmup_drift_mm: 5, warmup_time_constant_s: 240}\n";

std::string replaced(const std::string& from, const std::string& to) {
  std::string s = kResidual;
  return s.replace(s.find(from), from.size(), to);
}

TEST(TofResidual, SettingsReadEveryKeyAndRefuseMissingOrOutOfRange) {
  const SimResidualSettings none = read("").residual;
  EXPECT_EQ(none.wiggle_amplitude_mm, 0);
  EXPECT_EQ(none.pixel_offset_sigma_mm, 0);
  EXPECT_EQ(none.multipath_max_mm, 0);
  EXPECT_EQ(none.warmup_drift_mm, 0);
  const SimResidualSettings r = read(kResidual).residual;
  EXPECT_EQ(r.wiggle_amplitude_mm, 12);
  EXPECT_EQ(r.wiggle_period_m, 1.5);
  EXPECT_EQ(r.wiggle_phase_rad, -1);
  EXPECT_EQ(r.slope_mm_per_m, 2);
  EXPECT_EQ(r.pixel_offset_sigma_mm, 3);
  EXPECT_EQ(r.reflectivity_bias_mm_per_decade, -2);
  EXPECT_EQ(r.reference_amplitude, 1000);
  EXPECT_EQ(r.multipath_max_mm, 15);
  EXPECT_EQ(r.warmup_drift_mm, 5);
  EXPECT_EQ(r.warmup_time_constant_s, 240);
  EXPECT_EQ(r.on_before_start_s, 0) << "optional: switched on with the process";
  EXPECT_EQ(
      read(replaced("warmup_time_constant_s: 240", "warmup_time_constant_s: 240, on_before_start_s: 1200"))
          .residual.on_before_start_s,
      1200);
  const std::string negative =
      error_of(replaced("warmup_time_constant_s: 240", "warmup_time_constant_s: 240, on_before_start_s: -1"));
  EXPECT_NE(negative.find("camera.sim.residual.on_before_start_s: expected a number in [0, 1e+07]"),
            std::string::npos)
      << negative;

  const std::string missing = error_of(replaced(", warmup_time_constant_s: 240", ""));
  EXPECT_NE(missing.find(
                "camera.sim.residual.warmup_time_constant_s: missing key, expected a number in [1, 86400]"),
            std::string::npos)
      << missing;
  const std::string period = error_of(replaced("wiggle_period_m: 1.5", "wiggle_period_m: 0.01"));
  EXPECT_NE(period.find("camera.sim.residual.wiggle_period_m: expected a number in [0.1, 100], got '0.01'"),
            std::string::npos)
      << period;
  const std::string sigma = error_of(replaced("pixel_offset_sigma_mm: 3", "pixel_offset_sigma_mm: -1"));
  EXPECT_NE(sigma.find("camera.sim.residual.pixel_offset_sigma_mm: expected a number in [0, 100]"),
            std::string::npos)
      << sigma;
  const std::string unknown = error_of(replaced("slope_mm_per_m", "slope_mm_per_metre"));
  EXPECT_NE(unknown.find("camera.sim.residual.slope_mm_per_m: missing key"), std::string::npos) << unknown;
  EXPECT_EQ(std::count(missing.begin(), missing.end(), '\n'), 0) << "one line";
}

TEST(TofResidual, DrawnCamerasLieInTheirRangesAndDifferBetweenSeeds) {
  for (uint64_t seed = 0; seed < 200; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const SimResidualSettings c = draw_imperfect_camera(seed, 4000);
    EXPECT_GE(c.wiggle_amplitude_mm, 5);
    EXPECT_LE(c.wiggle_amplitude_mm, 25);
    EXPECT_GE(c.wiggle_period_m, 1);
    EXPECT_LE(c.wiggle_period_m, 3);
    EXPECT_GE(c.wiggle_phase_rad, 0);
    EXPECT_LT(c.wiggle_phase_rad, 2 * M_PI);
    EXPECT_LE(std::abs(c.slope_mm_per_m), 5);
    EXPECT_GE(c.pixel_offset_sigma_mm, 2);
    EXPECT_LE(c.pixel_offset_sigma_mm, 5);
    EXPECT_GE(std::abs(c.reflectivity_bias_mm_per_decade), 1);
    EXPECT_LE(std::abs(c.reflectivity_bias_mm_per_decade), 4);
    EXPECT_EQ(c.reference_amplitude, 4000);
    EXPECT_GE(c.multipath_max_mm, 5);
    EXPECT_LE(c.multipath_max_mm, 20);
    EXPECT_GE(c.warmup_drift_mm, 3);
    EXPECT_LE(c.warmup_drift_mm, 8);
    EXPECT_GE(c.warmup_time_constant_s, 180);
    EXPECT_LE(c.warmup_time_constant_s, 480);
  }
  const SimResidualSettings a = draw_imperfect_camera(1, 4000);
  const SimResidualSettings b = draw_imperfect_camera(2, 4000);
  EXPECT_EQ(a.wiggle_amplitude_mm, draw_imperfect_camera(1, 4000).wiggle_amplitude_mm);
  EXPECT_NE(a.wiggle_amplitude_mm, b.wiggle_amplitude_mm);
  EXPECT_NE(a.wiggle_period_m, b.wiggle_period_m);
  EXPECT_NE(a.wiggle_phase_rad, b.wiggle_phase_rad);
  EXPECT_NE(a.slope_mm_per_m, b.slope_mm_per_m);
  EXPECT_NE(a.pixel_offset_sigma_mm, b.pixel_offset_sigma_mm);
  EXPECT_NE(a.reflectivity_bias_mm_per_decade, b.reflectivity_bias_mm_per_decade);
  EXPECT_NE(a.multipath_max_mm, b.multipath_max_mm);
  EXPECT_NE(a.warmup_drift_mm, b.warmup_drift_mm);
  EXPECT_NE(a.warmup_time_constant_s, b.warmup_time_constant_s);
  // Both signs of the amplitude bias occur.
  int negative = 0;
  for (uint64_t seed = 0; seed < 200; ++seed)
    negative += draw_imperfect_camera(seed, 4000).reflectivity_bias_mm_per_decade < 0;
  EXPECT_GT(negative, 60);
  EXPECT_LT(negative, 140);
}

}  // namespace
}  // namespace tofguard::sim
