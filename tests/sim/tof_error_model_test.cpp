#include "tofguard/sim/tof_error_model.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "sim_test_config.hpp"
#include "tofguard/sim/deterministic_random.hpp"

namespace tofguard::sim {
namespace {

using sim_test::test_intrinsics;
using sim_test::test_sim_config;

std::vector<float> wall(float z_m) {
  const Intrinsics in = test_intrinsics();
  return std::vector<float>(static_cast<size_t>(in.width) * in.height, z_m);
}

TEST(DeterministicRandom, IsFixedForASeed) {
  // Golden values: they change only if the engine or the distributions do,
  // which would change every simulated frame.
  DeterministicRandom r(42);
  EXPECT_DOUBLE_EQ(r.uniform(), 0.75515553295453897);
  EXPECT_DOUBLE_EQ(r.normal(), 0.019241066361427629);
  // Box-Muller normals: mean 0, standard deviation 1.
  DeterministicRandom s(7);
  double sum = 0, sum2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double x = s.normal();
    sum += x;
    sum2 += x * x;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(std::sqrt(sum2 / n), 1.0, 0.01);
}

// Over a flat wall seen perpendicularly, the error's mean and standard
// deviation per distance band are the configured e(r) and sigma(r).
TEST(TofErrorModel, NoiseStatisticsOverAFlatWallMatchTheModel) {
  const Intrinsics in = test_intrinsics();
  const TofErrorModel model(test_sim_config(), in);
  const camera::RadialToZ to_z(in);
  for (const double d : {0.5, 1.0, 2.0, 3.0, 4.0, 5.0}) {
    double sum = 0, sum2 = 0, expected_mean = 0, expected_var = 0;
    int count = 0;
    for (uint64_t frame = 0; frame < 6; ++frame) {
      const TofImage image = model.apply(wall(static_cast<float>(d)), frame, 0.0);
      for (int v = 52; v < 92; ++v) {
        for (int u = 67; u < 107; ++u) {
          const float z = image.depth_m[static_cast<size_t>(v) * in.width + u];
          ASSERT_GT(z, 0.0f) << "valid wall pixel at " << d << " m";
          const double f = to_z.factor(u, v);
          const double r = d / f;
          expected_mean += model.systematic_error_m(r) * f;
          expected_var += std::pow(model.noise_sigma_m(r) * f, 2);
          sum += z - d;
          sum2 += (z - d) * (z - d);
          ++count;
        }
      }
    }
    const double mean = sum / count;
    const double stddev = std::sqrt(sum2 / count - mean * mean);
    expected_mean /= count;
    const double expected_std = std::sqrt(expected_var / count);
    SCOPED_TRACE("wall at " + std::to_string(d) + " m");
    // The mean is known to within 4 standard errors.
    EXPECT_NEAR(mean, expected_mean, 4 * expected_std / std::sqrt(count));
    EXPECT_NEAR(stddev, expected_std, 0.03 * expected_std);
  }
  // The model's own numbers: 5 mm at 0.5 m, 30 mm at 5 m; error 58..148 mm.
  EXPECT_NEAR(model.noise_sigma_m(0.5), 0.005, 0.0001);
  EXPECT_NEAR(model.noise_sigma_m(5.0), 0.030, 0.0001);
  EXPECT_NEAR(model.systematic_error_m(0.5), 0.1338, 0.001);
}

TEST(TofErrorModel, SameSeedSameFramesOtherSeedOrFrameDiffers) {
  const Intrinsics in = test_intrinsics();
  SimCameraSettings config = test_sim_config();
  config.dark_pixel_probability = 0.01;
  const TofErrorModel a(config, in), b(config, in);
  config.seed = 2;
  const TofErrorModel c(config, in);
  const auto scene = wall(2.0f);
  const TofImage a3 = a.apply(scene, 3, 0.0);
  EXPECT_EQ(a3.depth_m, b.apply(scene, 3, 0.0).depth_m);
  EXPECT_EQ(a3.amplitude, b.apply(scene, 3, 0.0).amplitude);
  EXPECT_NE(a3.depth_m, a.apply(scene, 4, 0.0).depth_m);
  EXPECT_NE(a3.depth_m, c.apply(scene, 3, 0.0).depth_m);
}

TEST(TofErrorModel, AmplitudeFallsWithDistanceAndLowAmplitudeIsInvalid) {
  const Intrinsics in = test_intrinsics();
  const TofErrorModel model(test_sim_config(), in);
  const size_t centre = 72 * 176 + 87;
  // Perpendicular at the principal point: 4000 / r^2.
  EXPECT_NEAR(model.apply(wall(2.0f), 0, 0.0).amplitude[centre], 1000.0, 10.0);
  // At 9 m the amplitude (about 49) is below min_valid 60: every pixel invalid.
  const TofImage far = model.apply(wall(9.0f), 0, 0.0);
  for (float z : far.depth_m) ASSERT_EQ(z, 0.0f);
  EXPECT_NEAR(far.amplitude[centre], 4000.0 / 81.0, 1.0);
  // Nothing in the scene: no depth, no amplitude.
  const TofImage empty = model.apply(wall(0.0f), 0, 0.0);
  for (size_t i = 0; i < empty.depth_m.size(); ++i) {
    ASSERT_EQ(empty.depth_m[i], 0.0f);
    ASSERT_EQ(empty.amplitude[i], 0.0f);
  }
}

TEST(TofErrorModel, DarkNoiseInvalidatesTheConfiguredFraction) {
  const Intrinsics in = test_intrinsics();
  SimCameraSettings config = test_sim_config();
  config.dark_pixel_probability = 0.02;
  const TofErrorModel model(config, in);
  int invalid = 0, total = 0;
  for (uint64_t frame = 0; frame < 4; ++frame) {
    for (float z : model.apply(wall(1.5f), frame, 0.0).depth_m) {
      invalid += z == 0.0f;
      ++total;
    }
  }
  // 101376 pixels, expected 2028 +- 45 (1 sigma).
  EXPECT_NEAR(static_cast<double>(invalid) / total, 0.02, 0.002);
}

// A box 1 m away in front of a wall at 3 m: pixels whose depth is far from
// both surfaces' expected measurement lie only on the box's silhouette, and
// there are such pixels.
TEST(TofErrorModel, MixedPixelsAppearOnlyAtSilhouettes) {
  const Intrinsics in = test_intrinsics();
  const TofErrorModel model(test_sim_config(), in);
  const camera::RadialToZ to_z(in);
  std::vector<float> scene = wall(3.0f);
  auto inside = [](int u, int v) { return u >= 60 && u < 100 && v >= 50 && v < 90; };
  for (int v = 0; v < in.height; ++v)
    for (int u = 0; u < in.width; ++u)
      if (inside(u, v)) scene[static_cast<size_t>(v) * in.width + u] = 1.0f;
  auto on_silhouette = [&](int u, int v) {
    return inside(u, v) != inside(u + 1, v) || inside(u, v) != inside(u - 1, v) ||
           inside(u, v) != inside(u, v + 1) || inside(u, v) != inside(u, v - 1);
  };
  int mixed = 0, silhouette_pixels = 0;
  for (uint64_t frame = 0; frame < 3; ++frame) {
    const TofImage image = model.apply(scene, frame, 0.0);
    for (int v = 0; v < in.height; ++v) {
      for (int u = 0; u < in.width; ++u) {
        const size_t i = static_cast<size_t>(v) * in.width + u;
        const double f = to_z.factor(u, v);
        const double r = scene[i] / f;
        const double expected = (r + model.systematic_error_m(r)) * f;
        const bool outlier = std::abs(image.depth_m[i] - expected) > 6 * model.noise_sigma_m(r);
        silhouette_pixels += on_silhouette(u, v);
        if (!outlier) continue;
        ++mixed;
        EXPECT_TRUE(on_silhouette(u, v)) << "mixed pixel off the silhouette at " << u << "," << v;
        // A flying pixel lies between the two surfaces' measurements.
        EXPECT_GT(image.depth_m[i], 1.0 + model.systematic_error_m(1.0) - 0.1);
        EXPECT_LT(image.depth_m[i], 3.0 + model.systematic_error_m(3.0) + 0.2);
      }
    }
  }
  // 316 silhouette pixels per frame, 70 % of them mixed, most far from both.
  EXPECT_EQ(silhouette_pixels, 3 * 316);
  EXPECT_GT(mixed, silhouette_pixels / 3);
}

}  // namespace
}  // namespace tofguard::sim
