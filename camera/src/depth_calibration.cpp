#include "tofguard/camera/depth_calibration.hpp"

#include <set>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace tofguard::camera {

double evaluate_polynomial(const std::vector<double>& coefficients, double x) {
  double y = 0;
  for (auto it = coefficients.rbegin(); it != coefficients.rend(); ++it) y = y * x + *it;
  return y;
}

std::vector<double> fit_polynomial(const std::vector<double>& x, const std::vector<double>& y, int degree) {
  if (degree < 0) throw std::invalid_argument("polynomial degree " + std::to_string(degree));
  if (x.size() != y.size()) throw std::invalid_argument("fit_polynomial: x and y differ in size");
  const std::set<double> distinct(x.begin(), x.end());
  if (distinct.size() < static_cast<size_t>(degree) + 1) {
    throw std::invalid_argument("a degree-" + std::to_string(degree) + " fit needs at least " +
                                std::to_string(degree + 1) + " distinct distances, got " +
                                std::to_string(distinct.size()));
  }
  const int n = static_cast<int>(x.size());
  Eigen::MatrixXd vandermonde(n, degree + 1);
  Eigen::VectorXd rhs(n);
  for (int i = 0; i < n; ++i) {
    double power = 1;
    for (int j = 0; j <= degree; ++j) {
      vandermonde(i, j) = power;
      power *= x[i];
    }
    rhs(i) = y[i];
  }
  // Column-pivoting QR: stable for the mildly ill-conditioned Vandermonde
  // matrix (normal equations would square its condition number).
  const Eigen::VectorXd c = vandermonde.colPivHouseholderQr().solve(rhs);
  return std::vector<double>(c.data(), c.data() + c.size());
}

void DepthCalibration::apply_z(std::vector<float>* z_m, const RadialToZ& rays) const {
  if (z_m->size() != rays.pixel_count()) {
    throw std::invalid_argument("DepthCalibration: image of " + std::to_string(z_m->size()) +
                                " pixels, expected " + std::to_string(rays.pixel_count()));
  }
  for (size_t i = 0; i < z_m->size(); ++i) (*z_m)[i] = apply_z((*z_m)[i], rays.factor(i));
}

}  // namespace tofguard::camera
