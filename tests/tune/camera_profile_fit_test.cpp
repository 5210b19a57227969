// Commissioning's profile fit (camera_profile_fit.hpp) on synthetic rendered
// pairs of known residual distance error: the smooth correction where the
// samples crowd at one end of each distance bin, as a wall or a table
// makes them, applied where the camera measures.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "synthetic_frames.hpp"
#include "tofguard/common/camera_profile.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/tune/camera_profile_fit.hpp"

namespace tofguard::tune {
namespace {

// 160 x 120 pixels (synthetic_frames.hpp's intrinsics: fx = fy = 200,
// the principal point at the centre).
constexpr int kImageWidth = 160, kImageHeight = 120;
constexpr int kRowsPerSurface = 6;

// The residual radial error (measured minus true), mm: 10 mm per 0.1 m, the
// steepest a 25 mm wiggle of 1.6 m period reaches.
double residual_mm(double r_m) { return 100 * (r_m - 1.0); }

// Twenty surfaces of six rows each, surface k at a radial distance of
// 1.005 + 0.05 k m: every sample sits 5 mm above its 5 cm bin's lower edge.
// The camera reads residual_mm farther, plus N(0, 3 mm) noise.
std::vector<RenderedPair> crowded_frames(int count) {
  std::mt19937_64 random(7);
  std::normal_distribution<double> noise(0, 3);
  std::vector<RenderedPair> frames;
  for (int n = 0; n < count; ++n) {
    RenderedPair pair;
    const std::vector<int16_t> nothing(static_cast<size_t>(kImageWidth * kImageHeight), 0);
    pair.camera = test::depth_frame(nothing, n, kImageWidth, kImageHeight);
    pair.rendered = pair.camera;
    const depth_image_t& in = pair.rendered;
    pair.labels.width = kImageWidth;
    pair.labels.height = kImageHeight;
    pair.labels.num_robot_links = 0;
    pair.labels.num_links = 1;
    pair.labels.link_name = {"wall"};
    pair.labels.num_pixels = kImageWidth * kImageHeight;
    pair.labels.label.assign(static_cast<size_t>(kImageWidth * kImageHeight), kLabelEnvironmentFirst);
    for (int v = 0; v < kImageHeight; ++v) {
      const double r_m = 1.005 + 0.05 * (v / kRowsPerSurface);
      for (int u = 0; u < kImageWidth; ++u) {
        const size_t i = static_cast<size_t>(v) * kImageWidth + u;
        const double f = z_per_radial(in.fx, in.fy, in.cx, in.cy, u, v);
        pair.rendered.depth_mm[i] = static_cast<int16_t>(std::lround(1000 * r_m * f));
        pair.camera.depth_mm[i] =
            static_cast<int16_t>(std::lround(1000 * r_m * f + f * residual_mm(r_m) + noise(random)));
      }
    }
    frames.push_back(std::move(pair));
  }
  return frames;
}

// The profile fit of `frames` with 3 mm of noise and bins of 1000 samples.
ProfileFit fit_of(const std::vector<RenderedPair>& frames) {
  discrepancy::Tolerance tolerance;
  tolerance.noise = DepthNoise{3.0, 0.0};
  ProfileFitOptions options;
  options.min_bin_samples = 1000;
  return fit_camera_profile(frames, tolerance, 0.0, options);
}

// `pair`'s labels with one robot link, "forearm" (moved by a joint: no
// link_axis given), before the wall; no pixel labelled with it yet.
void add_forearm(RenderedPair* pair) {
  pair->labels.num_robot_links = 1;
  pair->labels.num_links = 2;
  pair->labels.link_name = {"forearm", "wall"};
}

TEST(CameraProfileFit, SmoothCorrectionHoldsWhereTheSamplesCrowdAtOneEndOfEachBin) {
  const ProfileFit fit = fit_of(crowded_frames(24));
  ASSERT_TRUE(fit.ok) << fit.error;
  // Between the surfaces' distances, the correction (I_dis / f: true minus
  // measured), applied at the distance the camera measures, is the
  // residual's negative. Taking each bin's median at the bin's centre (2 cm
  // above the samples) would be 2 mm off everywhere, and at the rendered
  // distance instead of the measured one up to 9 mm (the residual reaches
  // 95 mm, at 0.1 mm per mm).
  for (double r_m = 1.02; r_m < 1.95; r_m += 0.037) {
    const double measured_m = r_m + residual_mm(r_m) * 1e-3;
    EXPECT_NEAR(fit.profile.distance_correction_at(measured_m), -residual_mm(r_m), 0.25)
        << "at " << r_m << " m";
  }
  // Nothing left for the per-pixel offsets to take up but the noise of a
  // 24-frame mean (3 / sqrt(24) = 0.6 mm) and the whole millimetres (0.3
  // mm): the 2 mm a bin's centre would be off by would show here as well.
  EXPECT_GT(fit.mapped_pixels, kImageWidth * kImageHeight / 2);
  EXPECT_LT(fit.pixel_sigma_mm, 0.9);
}

// The per-pixel map is learned on surfaces no joint moves: a link's own
// error (here 8 mm of multipath on rows 0-5) moves with it and would be
// wrong for the scene behind when the link has gone.
TEST(CameraProfileFit, LearnsNoPixelOffsetFromAMovingLink) {
  std::vector<RenderedPair> frames = crowded_frames(24);
  for (RenderedPair& pair : frames) {
    add_forearm(&pair);
    for (size_t i = 0; i < static_cast<size_t>(kRowsPerSurface * kImageWidth); ++i) {
      pair.labels.label[i] = kLabelRobotFirst;
      pair.camera.depth_mm[i] = static_cast<int16_t>(pair.camera.depth_mm[i] + 8);
    }
  }
  const ProfileFit fit = fit_of(frames);
  ASSERT_TRUE(fit.ok) << fit.error;
  for (size_t i = 0; i < static_cast<size_t>(kRowsPerSurface * kImageWidth); ++i)
    ASSERT_EQ(fit.profile.pixel_correction_mm[i], 0.0f) << "pixel " << i;
  EXPECT_GT(fit.mapped_pixels, kImageWidth * (kImageHeight - kRowsPerSurface) / 2);
  EXPECT_LE(fit.mapped_pixels, kImageWidth * (kImageHeight - kRowsPerSurface));
}

// A checking recording whose arm comes nearer the camera than the learning
// one went: its pixels there get the correction's end value, a guess.
TEST(CameraProfileFit, CoverageCountsTheArmsPixelsOutsideTheProfilesRange) {
  const ProfileFit fit = fit_of(crowded_frames(24));
  ASSERT_TRUE(fit.ok) << fit.error;
  // The forearm on the first 12 rows: at 0.90 m on rows 0-5, outside the profile's 1.0-1.95 m; at
  // 1.30 m on rows 6-11, inside.
  std::vector<RenderedPair> checking = crowded_frames(2);
  for (RenderedPair& pair : checking) {
    add_forearm(&pair);
    const depth_image_t& in = pair.rendered;
    for (int v = 0; v < 2 * kRowsPerSurface; ++v) {
      const double r_m = v < kRowsPerSurface ? 0.90 : 1.30;
      for (int u = 0; u < kImageWidth; ++u) {
        const size_t i = static_cast<size_t>(v) * kImageWidth + u;
        const double f = z_per_radial(in.fx, in.fy, in.cx, in.cy, u, v);
        pair.labels.label[i] = kLabelRobotFirst;
        pair.rendered.depth_mm[i] = static_cast<int16_t>(std::lround(1000 * r_m * f));
        pair.camera.depth_mm[i] = static_cast<int16_t>(std::lround(1000 * r_m * f + f * residual_mm(r_m)));
      }
    }
  }
  const ProfileCoverage coverage = profile_coverage(fit.profile, checking, 0.0);
  EXPECT_EQ(coverage.pixels, 2 * 2 * kRowsPerSurface * kImageWidth) << "the arm's pixels only";
  EXPECT_EQ(coverage.outside, 2 * kRowsPerSurface * kImageWidth);
  EXPECT_NEAR(coverage.outside_share(), 0.5, 1e-9);
  EXPECT_GT(coverage.first_m, 0.95);
  EXPECT_NEAR(coverage.nearest_m, 0.90, 0.001) << "the model's distance, not the measured one";
  EXPECT_GT(coverage.outside_share(), kMaxShareOutsideProfile);
  // The learning recording itself is inside (its arm-free frames: none).
  EXPECT_EQ(profile_coverage(fit.profile, crowded_frames(2), 0.0).pixels, 0);
}

}  // namespace
}  // namespace tofguard::tune
