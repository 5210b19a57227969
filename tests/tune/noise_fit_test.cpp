// tofguard-tune's fit on synthetic samples of known noise (noise_fit.hpp):
// sigma(d) = a + b d^2 recovered from I_dis in whole millimetres with a
// bias that changes with depth and gross outliers; the neighbours'
// correlation of independent and of box-filtered noise; the score
// statistics of a biased N(0, 1).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tofguard/tune/noise_fit.hpp"

namespace tofguard::tune {
namespace {

// Samples of sigma(d) = a + b d^2 at depths uniform over [near_m, far_m],
// with a bias of 5 mm per metre, rounded to whole millimetres like the
// depth images; `outliers` of them replaced by +-300..800 mm.
NoiseSamples synthetic_samples(double a, double b, double near_m, double far_m, int count, double outliers,
                               uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> depth(near_m, far_m), unit(0, 1);
  std::normal_distribution<double> normal(0, 1);
  NoiseSamples samples;
  for (int k = 0; k < count; ++k) {
    const double d = depth(random);
    double dis = 5 * d + (a + b * d * d) * normal(random);
    if (unit(random) < outliers) dis = (unit(random) < 0.5 ? -1 : 1) * (300 + 500 * unit(random));
    samples.add(static_cast<int>(std::lround(d * 1000)), static_cast<int>(std::lround(dis)));
  }
  return samples;
}

TEST(NoiseFit, RecoversTheModelFromWholeMillimetres) {
  // sigma 8.5 mm at 0.5 m to 40 mm at 4 m: at the near end a MAD of 5.7
  // mm, which rounding to whole millimetres alone would get 10 % wrong.
  const NoiseFit fit = synthetic_samples(8.0, 2.0, 0.5, 4.0, 2'000'000, 0, 1).fit();
  ASSERT_TRUE(fit.ok) << fit.error;
  EXPECT_NEAR(fit.sigma_at_0m_mm, 8.0, 0.2);
  EXPECT_NEAR(fit.sigma_per_m2_mm, 2.0, 0.04);
  EXPECT_LT(fit.worst_bin_ratio_error, 0.03);
  // The bias is removed per bin, not counted as noise.
  EXPECT_NEAR(fit.median_mm_at(2000), 5 * 2.05, 0.5);
}

TEST(NoiseFit, GrossOutliersDoNotInflateIt) {
  const NoiseFit fit = synthetic_samples(4.0, 1.2, 0.8, 3.5, 1'000'000, 0.05, 2).fit();
  ASSERT_TRUE(fit.ok) << fit.error;
  // 5 % outliers move the MAD by about 6 % (the median of |x - m| moves to
  // the 0.5 / 0.95 quantile of the rest).
  EXPECT_NEAR(fit.sigma_mm(1.0), 5.2, 0.5);
  EXPECT_NEAR(fit.sigma_mm(3.0), 14.8, 1.2);
}

TEST(NoiseFit, RefusesTooNarrowADepthRange) {
  const NoiseFit fit = synthetic_samples(4.0, 1.2, 1.5, 1.8, 500'000, 0, 3).fit();
  EXPECT_FALSE(fit.ok);
  EXPECT_NE(fit.error.find("span only"), std::string::npos) << fit.error;
}

TEST(NoiseFit, RefusesTooFewSamples) {
  const NoiseFit fit = synthetic_samples(4.0, 1.2, 0.5, 4.0, 5'000, 0, 4).fit();
  EXPECT_FALSE(fit.ok);
  EXPECT_NE(fit.error.find("depth bins"), std::string::npos) << fit.error;
}

// White noise on a 176 x 144 image, box-filtered with radius `r` (0: none)
// and scaled back to unit variance.
std::vector<float> noise_image(int width, int height, int r, std::mt19937_64* random) {
  std::normal_distribution<double> normal(0, 1);
  std::vector<double> white(static_cast<size_t>(width) * height);
  for (double& w : white) w = normal(*random);
  std::vector<float> out(white.size(), 0.0f);
  const double scale = 1.0 / (2 * r + 1);  // sum of (2r+1)^2 unit variances -> 1
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      double sum = 0;
      for (int dv = -r; dv <= r; ++dv) {
        for (int du = -r; du <= r; ++du) {
          const int uu = std::clamp(u + du, 0, width - 1), vv = std::clamp(v + dv, 0, height - 1);
          sum += white[static_cast<size_t>(vv) * width + uu];
        }
      }
      out[static_cast<size_t>(v) * width + u] = static_cast<float>(sum * scale);
    }
  }
  return out;
}

TEST(SpatialCorrelation, IndependentPixelsAreOneSampleEach) {
  std::mt19937_64 random(5);
  SpatialCorrelation correlation;
  const std::vector<uint8_t> valid(176 * 144, 1);
  for (int k = 0; k < 20; ++k) correlation.add_frame(noise_image(176, 144, 0, &random), valid, 176, 144);
  EXPECT_NEAR(correlation.rho(0, 1), 0, 0.01);
  EXPECT_NEAR(correlation.rho(1, 1), 0, 0.01);
  EXPECT_LT(correlation.pixels_per_sample(), 1.1);
}

TEST(SpatialCorrelation, ABoxFilterIsItsFootprint) {
  std::mt19937_64 random(6);
  SpatialCorrelation correlation;
  std::vector<uint8_t> valid(176 * 144, 1);
  // Some pixels are no samples (invalid, silhouettes): pairs skip them.
  for (size_t i = 0; i < valid.size(); i += 7) valid[i] = 0;
  for (int k = 0; k < 20; ++k) correlation.add_frame(noise_image(176, 144, 1, &random), valid, 176, 144);
  // 3 x 3 box: rho 2/3 at lag 1, 1/3 at lag 2, 0 beyond: 3 x 3 = 9 pixels.
  EXPECT_NEAR(correlation.rho(0, 1), 2.0 / 3, 0.02);
  EXPECT_NEAR(correlation.rho(1, 2), 1.0 / 3, 0.02);
  EXPECT_NEAR(correlation.pixels_per_sample(), 9, 1.0);
}

TEST(ScoreStatistics, TheFrameToFramePartLeavesOutASlowBias) {
  std::mt19937_64 random(7);
  std::normal_distribution<double> normal(0, 1);
  ScoreStatistics statistics;
  const double information = 400;  // t = s / 20
  for (int k = 0; k < 20000; ++k) {
    const double bias_t = std::sin(k * 0.001);  // slow: about 0.5 on average in t^2
    statistics.add((bias_t + normal(random)) * std::sqrt(information), information);
  }
  statistics.add(1, 0);  // not seen: skipped, the chain broken
  EXPECT_EQ(statistics.count(), 20000);
  EXPECT_NEAR(statistics.variance(), 1.5, 0.1);
  EXPECT_NEAR(statistics.frame_to_frame_variance(), 1.0, 0.05);
}

}  // namespace
}  // namespace tofguard::tune
