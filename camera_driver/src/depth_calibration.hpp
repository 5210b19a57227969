#pragma once
// Distance calibration (issue 4, after the seed paper): a ToF camera's
// distance has a systematic error that depends on the distance itself (the
// "wiggling" error of the modulation). It is modelled as a polynomial p and
// removed before publishing:
//   d_calibrated = d - p(d),   p(d) = sum_i c[i] * d^i,
// with d the measured Z in metres and p(d) in metres. Metres keep the
// powers of d near 1 (d^5 is about 3e3 at 5 m, 3e18 in millimetres), so the
// least-squares fit is well conditioned.
#include <vector>

namespace tofguard::camera {

// p(d) = sum_i coefficients[i] * d^i (Horner).
double evaluate_polynomial(const std::vector<double>& coefficients, double x);

// Least-squares polynomial of `degree` through (x[i], y[i]), coefficients in
// ascending powers. Needs at least degree + 1 points with distinct x; throws
// std::invalid_argument otherwise.
std::vector<double> fit_polynomial(const std::vector<double>& x, const std::vector<double>& y,
                                   int degree);

class DepthCalibration {
 public:
  // Identity calibration (p = 0).
  DepthCalibration() = default;
  explicit DepthCalibration(std::vector<double> coefficients_m)
      : coefficients_m_(std::move(coefficients_m)) {}

  // p(d), metres.
  double error_m(double d_m) const { return evaluate_polynomial(coefficients_m_, d_m); }

  // d - p(d); an invalid input (<= 0) stays 0, and a result <= 0 becomes 0
  // (invalid) rather than a made-up distance.
  float apply(float d_m) const {
    if (!(d_m > 0)) return 0.0f;
    const double out = d_m - error_m(d_m);
    return out > 0 ? static_cast<float>(out) : 0.0f;
  }
  void apply(std::vector<float>* depth_m) const {
    for (float& d : *depth_m) d = apply(d);
  }

  const std::vector<double>& coefficients_m() const { return coefficients_m_; }

 private:
  std::vector<double> coefficients_m_;
};

}  // namespace tofguard::camera
