#pragma once
// Distance calibration (after the seed paper): a ToF camera's
// distance has a systematic error that depends on the distance itself (the
// "wiggling" error of the modulation). The camera measures the time of
// flight along each pixel's ray, so the error is a function of the radial
// distance d along the ray, not of Z. It is modelled as a polynomial p and
// removed before publishing:
//   d_calibrated = d - p(d),   p(d) = sum_i c[i] * d^i,
// with d the measured radial distance in metres and p(d) in metres. A Z
// image is calibrated per pixel through its ray: d = Z / f(u, v), with
// f = Z / r from the intrinsics (RadialToZ), then Z_calibrated =
// (d - p(d)) * f. Correcting Z with p(Z) instead would leave an error that
// grows with the distance from the image centre (p(r) - p(Z), and p(d) is
// not scaled by f). Metres keep the powers of d near 1 (d^5 is about 3e3 at
// 5 m, 3e18 in millimetres), so the least-squares fit is well conditioned.
#include <vector>

#include "tofguard/camera/depth_conversion.hpp"

namespace tofguard::camera {

// p(d) = sum_i coefficients[i] * d^i (Horner).
double evaluate_polynomial(const std::vector<double>& coefficients, double x);

// Least-squares polynomial of `degree` through (x[i], y[i]), coefficients in
// ascending powers. Needs at least degree + 1 points with distinct x; throws
// std::invalid_argument otherwise.
std::vector<double> fit_polynomial(const std::vector<double>& x, const std::vector<double>& y, int degree);

class DepthCalibration {
 public:
  // Identity calibration (p = 0).
  DepthCalibration() = default;
  explicit DepthCalibration(std::vector<double> coefficients_m)
      : coefficients_m_(std::move(coefficients_m)) {}

  // p(d), metres, d the radial distance in metres.
  double error_m(double d_m) const { return evaluate_polynomial(coefficients_m_, d_m); }

  // d - p(d) for a radial distance d; an invalid input (<= 0) stays 0, and
  // a result <= 0 becomes 0 (invalid) rather than a made-up distance.
  float apply_radial(float d_m) const {
    if (!(d_m > 0)) return 0.0f;
    const double out = d_m - error_m(d_m);
    return out > 0 ? static_cast<float>(out) : 0.0f;
  }
  // The Z of one pixel whose ray has Z / r = `z_per_radial`: corrected
  // along the ray and converted back to Z (0 stays 0).
  float apply_z(float z_m, float z_per_radial) const {
    return apply_radial(z_m / z_per_radial) * z_per_radial;
  }
  // Calibrates a row-major Z image (metres, 0 = invalid) of the rays' image
  // size in place. Throws std::invalid_argument for a wrong size.
  void apply_z(std::vector<float>* z_m, const RadialToZ& rays) const;

  const std::vector<double>& coefficients_m() const { return coefficients_m_; }

 private:
  std::vector<double> coefficients_m_;
};

}  // namespace tofguard::camera
