#include "tofguard/sim/tof_error_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

#include "tofguard/camera/depth_calibration.hpp"
#include "tofguard/sim/deterministic_random.hpp"

namespace tofguard::sim {
namespace {

// The point seen at pixel (u, v) with depth z, in the optical frame.
Eigen::Vector3d back_project(const Intrinsics& in, int u, int v, double z) {
  return Eigen::Vector3d((u - in.cx) / in.fx * z, (v - in.cy) / in.fy * z, z);
}

// 1. The ideal amplitude per pixel of a true depth image (w x h, m; 0:
// nothing seen): amplitude_at_1m * cos(incidence) / r^2.
std::vector<double> ideal_amplitude(const std::vector<float>& z_true, const Intrinsics& intrinsics,
                                    double jump, double amplitude_at_1m) {
  const int w = intrinsics.width;
  const int h = intrinsics.height;
  auto at = [&](int u, int v) { return static_cast<double>(z_true[static_cast<size_t>(v) * w + u]); };
  // Two neighbours lie on the same surface when both see something and
  // their depths differ by less than the silhouette jump.
  auto same_surface = [&](double a, double b) { return a > 0 && b > 0 && std::abs(a - b) <= jump; };
  std::vector<double> amplitude(z_true.size(), 0.0);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const double z = at(u, v);
      if (!(z > 0)) continue;
      const Eigen::Vector3d p = back_project(intrinsics, u, v, z);
      // Surface tangents from the neighbours on the same surface (central
      // difference when both sides are, one-sided otherwise).
      auto tangent = [&](int du, int dv, Eigen::Vector3d* t) {
        const int u0 = u - du, v0 = v - dv, u1 = u + du, v1 = v + dv;
        const bool before = u0 >= 0 && v0 >= 0 && same_surface(z, at(u0, v0));
        const bool after = u1 < w && v1 < h && same_surface(z, at(u1, v1));
        if (!before && !after) return false;
        const Eigen::Vector3d a = before ? back_project(intrinsics, u0, v0, at(u0, v0)) : p;
        const Eigen::Vector3d b = after ? back_project(intrinsics, u1, v1, at(u1, v1)) : p;
        *t = b - a;
        return true;
      };
      double cos_incidence = 1.0;
      Eigen::Vector3d tu, tv;
      if (tangent(1, 0, &tu) && tangent(0, 1, &tv)) {
        const Eigen::Vector3d normal = tu.cross(tv);
        if (normal.norm() > 0) cos_incidence = std::abs(normal.normalized().dot(p.normalized()));
      }
      const double r = p.norm();
      amplitude[static_cast<size_t>(v) * w + u] = amplitude_at_1m * cos_incidence / (r * r);
    }
  }
  return amplitude;
}

// 2. Mixed pixels: of pixel (u, v)'s 4 neighbours, the one across the
// largest step beyond the jump (other: its index, -1 for none), and whether
// one sees nothing.
struct MixedNeighbours {
  int other = -1;
  bool empty_neighbour = false;
};

MixedNeighbours mixed_neighbours(const std::vector<float>& z_true, int w, int h, int u, int v, double jump) {
  static constexpr int du[4] = {1, -1, 0, 0};
  static constexpr int dv[4] = {0, 0, 1, -1};
  const double z = z_true[static_cast<size_t>(v) * w + u];
  MixedNeighbours n;
  double largest_step = 0;
  for (int k = 0; k < 4; ++k) {
    const int un = u + du[k], vn = v + dv[k];
    if (un < 0 || vn < 0 || un >= w || vn >= h) continue;
    const size_t j = static_cast<size_t>(vn) * w + un;
    if (!(z_true[j] > 0)) {
      n.empty_neighbour = true;
    } else if (std::abs(z_true[j] - z) > jump && std::abs(z_true[j] - z) > largest_step) {
      largest_step = std::abs(z_true[j] - z);
      n.other = static_cast<int>(j);
    }
  }
  return n;
}

}  // namespace

TofErrorModel::TofErrorModel(const SimCameraSettings& config, const Intrinsics& intrinsics)
    : config_(config), intrinsics_(intrinsics), radial_to_z_(intrinsics) {}

double TofErrorModel::systematic_error_m(double r_m) const {
  return camera::evaluate_polynomial(config_.systematic_error_m, r_m);
}

double TofErrorModel::noise_sigma_m(double r_m) const {
  return (config_.noise_sigma0_mm + config_.noise_sigma_per_m2_mm * r_m * r_m) * 1e-3;
}

TofImage TofErrorModel::apply(const std::vector<float>& z_true, uint64_t frame_index) const {
  const int w = intrinsics_.width;
  const int h = intrinsics_.height;
  const size_t n = static_cast<size_t>(w) * h;
  if (z_true.size() != n) {
    throw std::invalid_argument("ToF error model: depth image of " + std::to_string(z_true.size()) +
                                " pixels, expected " + std::to_string(n));
  }
  const double jump = config_.mixed_pixel_jump_m;
  const std::vector<double> amplitude = ideal_amplitude(z_true, intrinsics_, jump, config_.amplitude_at_1m);

  TofImage out;
  out.width = w;
  out.height = h;
  out.depth_m.assign(n, 0.0f);
  out.amplitude.assign(n, 0.0f);
  DeterministicRandom random(mix_seed(config_.seed, frame_index));
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      // The same draws for every pixel, used or not (see the header).
      const double mix_draw = random.uniform();
      const double coverage = random.uniform();
      const double dark_draw = random.uniform();
      const double noise = random.normal();
      const double z = z_true[i];
      if (!(z > 0)) continue;
      const double factor = radial_to_z_.factor(u, v);
      double r = z / factor;
      double a = amplitude[i];

      // 2. Mixed pixels: the neighbour across the largest step.
      const MixedNeighbours mixed = mixed_neighbours(z_true, w, h, u, v, jump);
      const int other = mixed.other;
      if ((other >= 0 || mixed.empty_neighbour) && mix_draw < config_.mixed_pixel_probability) {
        if (other >= 0) {
          // The other surface, seen along this pixel's ray.
          const double r_other = z_true[other] / factor;
          const double a_other = amplitude[other];
          const double weight = coverage * a + (1 - coverage) * a_other;
          if (weight > 0) r = (coverage * a * r + (1 - coverage) * a_other * r_other) / weight;
          a = weight;
        } else {
          a *= coverage;
        }
      }
      out.amplitude[i] = static_cast<float>(a);

      // 4. Invalid pixels.
      if (a < config_.min_valid_amplitude || dark_draw < config_.dark_pixel_probability) continue;

      // 3. Systematic error and noise, along the ray.
      const double measured_r = r + systematic_error_m(r) + noise_sigma_m(r) * noise;
      if (measured_r > 0) out.depth_m[i] = static_cast<float>(measured_r * factor);
    }
  }
  return out;
}

}  // namespace tofguard::sim
