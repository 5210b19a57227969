#include "depth_calibration.hpp"

#include <gtest/gtest.h>

namespace tofguard::camera {
namespace {

TEST(Polynomial, EvaluatesAscendingPowers) {
  EXPECT_DOUBLE_EQ(evaluate_polynomial({1, 2, 3}, 2.0), 1 + 4 + 12);
  EXPECT_DOUBLE_EQ(evaluate_polynomial({}, 2.0), 0.0);
}

TEST(Polynomial, FitRecoversAFifthOrderPolynomial) {
  const std::vector<double> truth = {0.0186286, 0.388128, -0.376992, 0.131278, -0.0179423,
                                     0.000764776};
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

TEST(DepthCalibration, SubtractsTheErrorPolynomial) {
  const DepthCalibration cal({0.01, 0.02});  // p(d) = 0.01 + 0.02 d
  EXPECT_NEAR(cal.apply(2.0f), 2.0 - 0.05, 1e-6);
  EXPECT_EQ(cal.apply(0.0f), 0.0f);            // invalid stays invalid
  EXPECT_EQ(DepthCalibration({5.0}).apply(1.0f), 0.0f);  // never negative
  std::vector<float> image = {1.0f, 0.0f};
  cal.apply(&image);
  EXPECT_NEAR(image[0], 0.97, 1e-6);
  EXPECT_EQ(image[1], 0.0f);
}

}  // namespace
}  // namespace tofguard::camera
