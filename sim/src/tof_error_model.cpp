#include "tofguard/sim/tof_error_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

#include "tofguard/camera/depth_calibration.hpp"
#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/sim/deterministic_random.hpp"

namespace tofguard::sim {
namespace {

// What the true image shows per pixel (row-major): the seen point in the
// optical frame, its radial distance (0: nothing seen) and the surface's
// unit normal there, turned towards the camera (zero where unknown:
// nothing seen, or no neighbour on the same surface in u or v).
struct SurfaceGeometry {
  std::vector<Eigen::Vector3d> point_m;
  std::vector<double> r_m;
  std::vector<Eigen::Vector3d> normal;
};

SurfaceGeometry surface_geometry(const std::vector<float>& z_true, const Intrinsics& intrinsics,
                                 double jump) {
  const int w = intrinsics.width;
  const int h = intrinsics.height;
  auto at = [&](int u, int v) { return static_cast<double>(z_true[static_cast<size_t>(v) * w + u]); };
  // Two neighbours lie on the same surface when both see something and
  // their depths differ by less than the silhouette jump.
  auto same_surface = [&](double a, double b) { return a > 0 && b > 0 && std::abs(a - b) <= jump; };
  SurfaceGeometry g;
  g.point_m.assign(z_true.size(), Eigen::Vector3d::Zero());
  g.r_m.assign(z_true.size(), 0.0);
  g.normal.assign(z_true.size(), Eigen::Vector3d::Zero());
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const double z = at(u, v);
      if (!(z > 0)) continue;
      const size_t i = static_cast<size_t>(v) * w + u;
      const Eigen::Vector3d p = optical_point_m(intrinsics, u, v, z);
      g.point_m[i] = p;
      g.r_m[i] = p.norm();
      // Surface tangents from the neighbours on the same surface (central
      // difference when both sides are, one-sided otherwise).
      auto tangent = [&](int du, int dv, Eigen::Vector3d* t) {
        const int u0 = u - du, v0 = v - dv, u1 = u + du, v1 = v + dv;
        const bool before = u0 >= 0 && v0 >= 0 && same_surface(z, at(u0, v0));
        const bool after = u1 < w && v1 < h && same_surface(z, at(u1, v1));
        if (!before && !after) return false;
        const Eigen::Vector3d a = before ? optical_point_m(intrinsics, u0, v0, at(u0, v0)) : p;
        const Eigen::Vector3d b = after ? optical_point_m(intrinsics, u1, v1, at(u1, v1)) : p;
        *t = b - a;
        return true;
      };
      Eigen::Vector3d tu, tv;
      if (!tangent(1, 0, &tu) || !tangent(0, 1, &tv)) continue;
      const Eigen::Vector3d normal = tu.cross(tv);
      if (!(normal.norm() > 0)) continue;
      g.normal[i] = normal.dot(p) > 0 ? Eigen::Vector3d(-normal.normalized()) : normal.normalized();
    }
  }
  return g;
}

// 1. The ideal amplitude per pixel: amplitude_at_1m * cos(incidence) / r^2
// (cos = 1 where the normal is unknown).
std::vector<double> ideal_amplitude(const SurfaceGeometry& g, double amplitude_at_1m) {
  std::vector<double> amplitude(g.point_m.size(), 0.0);
  for (size_t i = 0; i < amplitude.size(); ++i) {
    const double r = g.r_m[i];
    if (!(r > 0)) continue;
    const double cos_incidence = g.normal[i].isZero() ? 1.0 : std::abs(g.normal[i].dot(g.point_m[i] / r));
    amplitude[i] = amplitude_at_1m * cos_incidence / (r * r);
  }
  return amplitude;
}

// 4. Multipath (the header's approximation): per pixel the extra radial
// distance, metres; all zero for max_m 0.
constexpr int kMultipathWindowRadiusPx = 4;  // a 9x9 window
constexpr double kMultipathMinStepM = 0.01;
constexpr double kMultipathRangeM = 0.5;

std::vector<double> multipath_m(const SurfaceGeometry& g, int w, int h, double max_m) {
  std::vector<double> extra(g.point_m.size(), 0.0);
  if (!(max_m > 0)) return extra;
  constexpr int k = kMultipathWindowRadiusPx;
  constexpr double window_pixels = (2 * k + 1) * (2 * k + 1) - 1;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      const double r = g.r_m[i];
      if (!(r > 0)) continue;
      const Eigen::Vector3d& p = g.point_m[i];
      double facing_sum = 0;
      for (int vj = std::max(0, v - k); vj <= std::min(h - 1, v + k); ++vj) {
        for (int uj = std::max(0, u - k); uj <= std::min(w - 1, u + k); ++uj) {
          const size_t j = static_cast<size_t>(vj) * w + uj;
          // Cheapest test first: most neighbours are not farther.
          if (!(g.r_m[j] > r + kMultipathMinStepM) || g.normal[j].isZero()) continue;
          const Eigen::Vector3d to_pixel = p - g.point_m[j];
          const double distance = to_pixel.norm();
          if (distance > kMultipathRangeM) continue;
          facing_sum += std::max(0.0, g.normal[j].dot(to_pixel) / distance);
        }
      }
      extra[i] = max_m * std::min(1.0, 2.0 * facing_sum / window_pixels);
    }
  }
  return extra;
}

// The stream the fixed-pattern noise is drawn from: one no frame index
// reaches (2^64 - 2^16 frames at 30 Hz take 1.9e10 years).
constexpr uint64_t kPixelOffsetStream = 0xffffffffffff0000ULL;

// N(0, sigma) per pixel, metres; empty for sigma 0.
std::vector<float> draw_pixel_offsets_m(uint64_t seed, size_t pixels, double sigma_m) {
  if (!(sigma_m > 0)) return {};
  DeterministicRandom random(mix_seed(seed, kPixelOffsetStream));
  std::vector<float> offsets(pixels);
  for (float& offset : offsets) offset = static_cast<float>(sigma_m * random.normal());
  return offsets;
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
    : config_(config),
      intrinsics_(intrinsics),
      radial_to_z_(intrinsics),
      pixel_offsets_m_(draw_pixel_offsets_m(config.seed,
                                            static_cast<size_t>(intrinsics.width) * intrinsics.height,
                                            config.residual.pixel_offset_sigma_mm * 1e-3)) {}

double TofErrorModel::systematic_error_m(double r_m) const {
  return camera::evaluate_polynomial(config_.systematic_error_m, r_m);
}

double TofErrorModel::noise_sigma_m(double r_m) const {
  return (config_.noise_sigma0_mm + config_.noise_sigma_per_m2_mm * r_m * r_m) * 1e-3;
}

double TofErrorModel::wiggle_error_m(double r_m) const {
  const SimResidualSettings& c = config_.residual;
  const double wiggle_mm =
      c.wiggle_amplitude_mm * std::sin(2 * M_PI * r_m / c.wiggle_period_m + c.wiggle_phase_rad);
  return (wiggle_mm + c.slope_mm_per_m * r_m) * 1e-3;
}

double TofErrorModel::amplitude_bias_m(double amplitude) const {
  const SimResidualSettings& c = config_.residual;
  if (c.reflectivity_bias_mm_per_decade == 0) return 0;
  return c.reflectivity_bias_mm_per_decade * std::log10(std::max(amplitude, 1.0) / c.reference_amplitude) *
         1e-3;
}

double TofErrorModel::warmup_drift_m(double time_since_start_s) const {
  const SimResidualSettings& c = config_.residual;
  const double on_s = c.on_before_start_s + time_since_start_s;
  return c.warmup_drift_mm * (1 - std::exp(-on_s / c.warmup_time_constant_s)) * 1e-3;
}

double TofErrorModel::pixel_offset_m(int u, int v) const {
  if (pixel_offsets_m_.empty()) return 0;
  return pixel_offsets_m_[static_cast<size_t>(v) * intrinsics_.width + u];
}

TofImage TofErrorModel::apply(const std::vector<float>& z_true, uint64_t frame_index,
                              double time_since_start_s) const {
  const int w = intrinsics_.width;
  const int h = intrinsics_.height;
  const size_t n = static_cast<size_t>(w) * h;
  if (z_true.size() != n) {
    throw std::invalid_argument("ToF error model: depth image of " + std::to_string(z_true.size()) +
                                " pixels, expected " + std::to_string(n));
  }
  const double jump = config_.mixed_pixel_jump_m;
  const SurfaceGeometry geometry = surface_geometry(z_true, intrinsics_, jump);
  const std::vector<double> amplitude = ideal_amplitude(geometry, config_.amplitude_at_1m);
  const std::vector<double> multipath = multipath_m(geometry, w, h, config_.residual.multipath_max_mm * 1e-3);
  const double drift = warmup_drift_m(time_since_start_s);

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

      // 5. Invalid pixels.
      if (a < config_.min_valid_amplitude || dark_draw < config_.dark_pixel_probability) continue;

      // 3. and 4. Systematic error, residual errors and noise, along the ray.
      const double residual =
          wiggle_error_m(r) + pixel_offset_m(u, v) + amplitude_bias_m(a) + multipath[i] + drift;
      const double measured_r = r + systematic_error_m(r) + residual + noise_sigma_m(r) * noise;
      if (measured_r > 0) out.depth_m[i] = static_cast<float>(measured_r * factor);
    }
  }
  return out;
}

SimResidualSettings draw_imperfect_camera(uint64_t seed, double reference_amplitude) {
  DeterministicRandom random(seed);
  auto between = [&](double lo, double hi) { return lo + (hi - lo) * random.uniform(); };
  SimResidualSettings c;
  // The order of the draws is part of the contract: the same seed gives
  // the same camera in every version that keeps it.
  c.wiggle_amplitude_mm = between(5, 25);
  c.wiggle_period_m = between(1, 3);
  c.wiggle_phase_rad = between(0, 2 * M_PI);
  c.slope_mm_per_m = between(-5, 5);
  c.pixel_offset_sigma_mm = between(2, 5);
  const double bias_mm_per_decade = between(1, 4);
  c.reflectivity_bias_mm_per_decade = random.uniform() < 0.5 ? -bias_mm_per_decade : bias_mm_per_decade;
  c.reference_amplitude = reference_amplitude;
  c.multipath_max_mm = between(5, 20);
  c.warmup_drift_mm = between(3, 8);
  c.warmup_time_constant_s = between(3 * 60, 8 * 60);
  return c;
}

}  // namespace tofguard::sim
