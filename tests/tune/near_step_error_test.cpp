// The near side of rendered steps (near_step_error.hpp) on synthetic frames
// of the default arm's boxes (synthetic_frames.hpp) whose near-step error
// changes over the recording, as a camera's multipath does with the pose.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "synthetic_frames.hpp"
#include "tofguard/tune/near_step_error.hpp"

namespace tofguard::tune {
namespace {

constexpr double kNoiseMm = 3;
constexpr double kSilhouetteJumpMm = 50;
constexpr double kNamingGateSigmas = 4;
constexpr double kSmoothAllowanceMm = 0.5;

constexpr double kBandStepMm = 10;

// `seconds` of 30 Hz frames of the still `arm` (the default arm's boxes
// unless given) before the floor: link2 (label 3) reads
// `link2_farther_mm(second)` farther, every pixel N(0, 3 mm) of noise.
template <typename Farther>
std::vector<RenderedPair> frames_with_link2_farther(int seconds, Farther link2_farther_mm,
                                                    const std::vector<test::Box>& arm = test::default_arm()) {
  std::mt19937_64 random(11);
  std::normal_distribution<double> noise(0, kNoiseMm);
  const test::SyntheticImage model = test::draw(arm);
  std::vector<RenderedPair> frames;
  for (int k = 0; k < 30 * seconds; ++k) {
    RenderedPair pair;
    pair.rendered = test::depth_frame(model.depth_mm, k);
    pair.labels = test::labels_frame(model.label, k);
    pair.camera = pair.rendered;
    for (size_t i = 0; i < model.depth_mm.size(); ++i) {
      const double farther_mm = model.label[i] == 3 ? link2_farther_mm(k / 30) : 0.0;
      pair.camera.depth_mm[i] =
          static_cast<int16_t>(std::lround(model.depth_mm[i] + farther_mm + noise(random)));
    }
    frames.push_back(std::move(pair));
  }
  return frames;
}

NearStepError measure(const std::vector<RenderedPair>& frames, double band_step_mm = kBandStepMm) {
  NoiseFit smooth;  // no smooth part (no bins), sigma 3 mm
  smooth.sigma_at_0m_mm = kNoiseMm;
  return measure_near_step_error(frames, kSilhouetteJumpMm, band_step_mm, kNamingGateSigmas, smooth,
                                 kSmoothAllowanceMm);
}

TEST(NearStepError, ALinksAllowanceIsItsLargestOneSecondMeanNotTheRecordingsMean) {
  // 4 mm farther over the first three seconds, none over the last three:
  // the recording's mean is 2 mm.
  const NearStepError error =
      measure(frames_with_link2_farther(6, [](int second) { return second < 3 ? 4.0 : 0.0; }));
  // link2's 20 rows lie within 10 px of the floor; each of its rings reads
  // 2 mm farther on the recording's mean.
  EXPECT_EQ(error.band_px, 10);
  double largest_ring_mean_mm = 0;
  for (double mean_mm : error.ring_mean_mm)
    largest_ring_mean_mm = std::max(largest_ring_mean_mm, std::abs(mean_mm));
  EXPECT_NEAR(largest_ring_mean_mm, 2.0, 0.3);
  ASSERT_EQ(error.bias_by_link_mm.count("link2"), 1u);
  EXPECT_NEAR(error.bias_by_link_mm.at("link2"), 4.0 - kSmoothAllowanceMm, 0.2);
  EXPECT_EQ(error.link, "link2");
  EXPECT_EQ(error.bias_mm, error.bias_by_link_mm.at("link2"));
  // link1 reads as far as it is: its allowance is its noise's, well below
  // link2's.
  ASSERT_EQ(error.bias_by_link_mm.count("link1"), 1u);
  EXPECT_LT(error.bias_by_link_mm.at("link1"), 0.2);
}

TEST(NearStepError, AConcaveCornerUnderTheSilhouetteJumpIsMeasuredFromTheBandsStep) {
  // link2 2 cm before link1, whose face surrounds it by 40 px or more: no
  // silhouette (a step over 5 cm) lies within the rings of link2's pixels,
  // only the 2 cm corner. link2 reads 4 mm farther throughout.
  const std::vector<test::Box> corner = {{20, 20, 156, 130, test::kArmMm, 2},
                                         {70, 60, 110, 80, test::kArmMm - 20, 3}};
  const auto frames = frames_with_link2_farther(
      3, [](int) { return 4.0; }, corner);
  const NearStepError from_band_step = measure(frames);
  EXPECT_EQ(from_band_step.band_step_mm, kBandStepMm);
  EXPECT_GT(from_band_step.band_px, 0);
  ASSERT_EQ(from_band_step.bias_by_link_mm.count("link2"), 1u);
  EXPECT_NEAR(from_band_step.bias_by_link_mm.at("link2"), 4.0 - kSmoothAllowanceMm, 0.3);
  EXPECT_EQ(from_band_step.link, "link2");
  // Measured from the silhouette jump, the corner is no step: no band, and
  // link2's 4 mm would accumulate in its joint's test.
  const NearStepError from_silhouettes = measure(frames, kSilhouetteJumpMm);
  EXPECT_EQ(from_silhouettes.bias_by_link_mm.count("link2"), 0u);
}

TEST(NearStepError, ALinksCornersDoNotDiluteItsSilhouettesAllowance) {
  // link2 2 cm before link1 on its left, over the floor on its right: its
  // pixels within 12 px of the floor (columns 128 on) read 4 mm farther
  // (multipath beside a silhouette), its many pixels by link1's corner
  // read as far as they are. Measured as one class, the corner's pixels
  // would lower the mean.
  const std::vector<test::Box> arm = {{20, 20, 140, 130, test::kArmMm, 2},
                                      {60, 60, 160, 100, test::kArmMm - 20, 3}};
  const test::SyntheticImage model = test::draw(arm);
  std::mt19937_64 random(12);
  std::normal_distribution<double> noise(0, kNoiseMm);
  std::vector<RenderedPair> frames;
  for (int k = 0; k < 90; ++k) {
    RenderedPair pair;
    pair.rendered = test::depth_frame(model.depth_mm, k);
    pair.labels = test::labels_frame(model.label, k);
    pair.camera = pair.rendered;
    for (size_t i = 0; i < model.depth_mm.size(); ++i) {
      const int u = static_cast<int>(i) % test::kWidth;
      const double farther_mm = model.label[i] == 3 && u >= 128 ? 4.0 : 0.0;
      pair.camera.depth_mm[i] =
          static_cast<int16_t>(std::lround(model.depth_mm[i] + farther_mm + noise(random)));
    }
    frames.push_back(std::move(pair));
  }
  const NearStepError error = measure(frames);
  EXPECT_GT(error.silhouette_band_px, 0);
  ASSERT_EQ(error.bias_by_link_mm.count("link2"), 1u);
  EXPECT_NEAR(error.bias_by_link_mm.at("link2"), 4.0 - kSmoothAllowanceMm, 0.4);
  EXPECT_LT(error.corner_bias_mm, 0.5) << "the corner reads as far as it is";
}

TEST(NearStepError, ACameraWithoutNearStepErrorGetsNoBand) {
  const NearStepError error = measure(frames_with_link2_farther(6, [](int) { return 0.0; }));
  EXPECT_EQ(error.band_px, 0);
  EXPECT_TRUE(error.bias_by_link_mm.empty());
  EXPECT_EQ(error.bias_mm, 0.0);
}

}  // namespace
}  // namespace tofguard::tune
