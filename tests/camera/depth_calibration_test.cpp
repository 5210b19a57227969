#include "tofguard/camera/depth_calibration.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "sim_test_config.hpp"
#include "tofguard/sim/tof_error_model.hpp"

namespace tofguard::camera {
namespace {

TEST(Polynomial, EvaluatesAscendingPowers) {
  EXPECT_DOUBLE_EQ(evaluate_polynomial({1, 2, 3}, 2.0), 1 + 4 + 12);
  EXPECT_DOUBLE_EQ(evaluate_polynomial({}, 2.0), 0.0);
}

TEST(Polynomial, FitRecoversAFifthOrderPolynomial) {
  const std::vector<double> truth = {0.0186286, 0.388128, -0.376992, 0.131278, -0.0179423, 0.000764776};
  std::vector<double> x, y;
  for (double d = 0.5; d <= 5.0001; d += 0.25) {
    x.push_back(d);
    y.push_back(evaluate_polynomial(truth, d));
  }
  const auto c = fit_polynomial(x, y, 5);
  ASSERT_EQ(c.size(), 6u);
  for (size_t i = 0; i < 6; ++i) EXPECT_NEAR(c[i], truth[i], 1e-8) << "coefficient " << i;
}

TEST(Polynomial, FitNeedsDegreePlusOneDistinctDistances) {
  try {
    fit_polynomial({1, 2, 3, 3, 3}, {0, 0, 0, 0, 0}, 3);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "a degree-3 fit needs at least 4 distinct distances, got 3");
  }
}

TEST(DepthCalibration, SubtractsTheErrorPolynomialAlongTheRay) {
  const DepthCalibration cal({0.01, 0.02});  // p(d) = 0.01 + 0.02 d
  EXPECT_NEAR(cal.apply_radial(2.0f), 2.0 - 0.05, 1e-6);
  EXPECT_EQ(cal.apply_radial(0.0f), 0.0f);                      // invalid stays invalid
  EXPECT_EQ(DepthCalibration({5.0}).apply_radial(1.0f), 0.0f);  // never negative
  // A pixel whose ray has Z / r = 0.8: Z 2 m is r 2.5 m, corrected to
  // 2.5 - 0.06 = 2.44 m along the ray, Z 1.952 m.
  EXPECT_NEAR(cal.apply_z(2.0f, 0.8f), 1.952, 1e-6);
  // A 2x2 image: pixel (0, 0) is off the principal point, (1, 1) on it.
  Intrinsics in;
  in.width = 2;
  in.height = 2;
  in.fx = in.fy = 1.0;
  in.cx = in.cy = 1.0;
  const RadialToZ rays(in);
  std::vector<float> image = {2.0f, 0.0f, 1.0f, 1.0f};
  cal.apply_z(&image, rays);
  const double f00 = 1 / std::sqrt(3.0);  // ray (-1, -1, 1)
  EXPECT_NEAR(image[0], (2.0 / f00 - (0.01 + 0.02 * 2.0 / f00)) * f00, 1e-6);
  EXPECT_EQ(image[1], 0.0f);
  EXPECT_NEAR(image[3], 1.0 - 0.03, 1e-6);  // on the axis, Z = r
  std::vector<float> wrong_size(3, 1.0f);
  EXPECT_THROW(cal.apply_z(&wrong_size, rays), std::invalid_argument);
}

// The simulated camera's systematic error lives along the ray; a
// calibration that inverts it removes it from the whole image, corners
// included, while the same polynomial applied to Z (the old calibration)
// leaves millimetres that grow away from the image centre.
TEST(DepthCalibration, RemovesTheSimulatedRadialErrorEverywhereInTheImage) {
  const Intrinsics in = sim::sim_test::test_intrinsics();
  sim::SimCameraSettings config = sim::sim_test::test_sim_config();
  config.noise_sigma0_mm = 0;
  config.noise_sigma_per_m2_mm = 0;
  const sim::TofErrorModel model(config, in);
  // p(d) with d = r + e(r) the measured radial distance: the inverse of e.
  std::vector<double> measured, error;
  for (double r = 0.4; r <= 5.0; r += 0.02) {
    measured.push_back(r + model.systematic_error_m(r));
    error.push_back(model.systematic_error_m(r));
  }
  const DepthCalibration cal(fit_polynomial(measured, error, 7));
  const RadialToZ rays(in);
  for (const double z : {0.8, 1.5, 2.5, 4.0}) {  // corners: r up to 4.5 m
    SCOPED_TRACE("plane at Z " + std::to_string(z) + " m");
    const std::vector<float> plane(static_cast<size_t>(in.width) * in.height, static_cast<float>(z));
    const sim::TofImage image = model.apply(plane, 0, 0.0);
    std::vector<float> calibrated = image.depth_m;
    cal.apply_z(&calibrated, rays);
    double worst_mm = 0, worst_z_only_mm = 0;
    int valid = 0;
    for (size_t i = 0; i < calibrated.size(); ++i) {
      if (!(image.depth_m[i] > 0)) continue;
      ++valid;
      worst_mm = std::max(worst_mm, std::abs(calibrated[i] - z) * 1e3);
      worst_z_only_mm = std::max(worst_z_only_mm, std::abs(cal.apply_radial(image.depth_m[i]) - z) * 1e3);
    }
    EXPECT_GT(valid, in.width * in.height * 9 / 10);
    EXPECT_LT(worst_mm, 0.5);
    EXPECT_GT(worst_z_only_mm, 3.0);
  }
}

}  // namespace
}  // namespace tofguard::camera
