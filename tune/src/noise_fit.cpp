#include "tofguard/tune/noise_fit.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tofguard::tune {
namespace {

// 1 / Phi^-1(3/4): MAD -> sigma for normal noise.
constexpr double kMadToSigma = 1.482602218505602;
// The variance of kMadToSigma * MAD is about 1.36 sigma^2 / n (the MAD's
// asymptotic efficiency for normal data is 37 %).
constexpr double kMadVarianceFactor = 1.36;
// The fitted bins must span at least this much depth, m: over less, b
// (per m^2) is not told from a.
constexpr double kMinDepthSpanM = 0.5;
// Residuals beyond this many sigmas are clipped before correlating.
constexpr double kClipSigmas = 4.0;

// The grouped-data CDF of a histogram of whole millimetres (value v spread
// uniformly over [v - 0.5, v + 0.5]): F(x) in counts.
class GroupedCdf {
 public:
  GroupedCdf(const std::vector<int64_t>& histogram, int offset)
      : offset_(offset), cumulative_(histogram.size() + 1, 0) {
    for (size_t i = 0; i < histogram.size(); ++i) cumulative_[i + 1] = cumulative_[i] + histogram[i];
  }
  double total() const { return static_cast<double>(cumulative_.back()); }
  double operator()(double x_mm) const {
    // Bin i covers [i - offset - 0.5, i - offset + 0.5).
    const double position = x_mm + offset_ + 0.5;
    if (position <= 0) return 0;
    const auto size = static_cast<double>(cumulative_.size() - 1);
    if (position >= size) return total();
    const auto i = static_cast<size_t>(position);
    const double fraction = position - static_cast<double>(i);
    return static_cast<double>(cumulative_[i]) +
           fraction * static_cast<double>(cumulative_[i + 1] - cumulative_[i]);
  }
  // The smallest x with F(x) >= target (bisection; F is monotonic).
  double inverse(double target) const {
    double lo = -offset_ - 1.0, hi = static_cast<double>(cumulative_.size()) - offset_;
    for (int k = 0; k < 60; ++k) {
      const double mid = 0.5 * (lo + hi);
      ((*this)(mid) >= target ? hi : lo) = mid;
    }
    return hi;
  }

 private:
  int offset_;
  std::vector<int64_t> cumulative_;
};

}  // namespace

NoiseSamples::NoiseSamples(const NoiseFitOptions& options) : options_(options) {}

int NoiseSamples::bin_of(int depth_mm) const {
  return static_cast<int>(std::floor(depth_mm * 1e-3 / options_.bin_m));
}

void NoiseSamples::add(int depth_mm, int dis_mm) {
  if (depth_mm <= 0) return;
  const int b = bin_of(depth_mm);
  if (b >= static_cast<int>(bins_.size())) bins_.resize(static_cast<size_t>(b) + 1);
  Bin& bin = bins_[static_cast<size_t>(b)];
  if (bin.histogram.empty()) bin.histogram.assign(2 * static_cast<size_t>(options_.range_mm) + 1, 0);
  const int clamped = std::clamp(dis_mm, -options_.range_mm, options_.range_mm);
  bin.histogram[static_cast<size_t>(clamped + options_.range_mm)]++;
  const double d_m = depth_mm * 1e-3;
  ++bin.count;
  bin.sum_depth_m += d_m;
  bin.sum_depth2_m2 += d_m * d_m;
  ++total_;
}

void NoiseSamples::robust(const Bin& bin, double* median_mm, double* sigma_mm) const {
  const GroupedCdf cdf(bin.histogram, options_.range_mm);
  const double half = 0.5 * cdf.total();
  const double m = cdf.inverse(half);
  // MAD: the a with F(m + a) - F(m - a) = half (bisection; monotonic in a).
  double lo = 0, hi = 2.0 * options_.range_mm + 2;
  for (int k = 0; k < 60; ++k) {
    const double a = 0.5 * (lo + hi);
    ((cdf(m + a) - cdf(m - a)) >= half ? hi : lo) = a;
  }
  *median_mm = m;
  *sigma_mm = kMadToSigma * hi;
}

double NoiseFit::median_mm_at(int depth_mm) const {
  if (depth_mm <= 0) return 0;
  const auto b = static_cast<size_t>(std::floor(depth_mm * 1e-3 / bin_m));
  return b < bin_median_mm.size() ? bin_median_mm[b] : 0.0;
}

NoiseFit NoiseSamples::fit() const {
  NoiseFit fit;
  fit.bin_m = options_.bin_m;
  fit.bin_median_mm.assign(bins_.size(), 0.0);
  for (size_t b = 0; b < bins_.size(); ++b) {
    const Bin& bin = bins_[b];
    if (bin.count == 0) continue;
    DepthBin out;
    robust(bin, &out.median_mm, &out.sigma_mm);
    fit.bin_median_mm[b] = out.median_mm;
    if (bin.count < options_.min_bin_samples) continue;
    out.samples = bin.count;
    out.depth_m = bin.sum_depth_m / static_cast<double>(bin.count);
    out.depth2_m2 = bin.sum_depth2_m2 / static_cast<double>(bin.count);
    fit.bins.push_back(out);
    fit.samples += bin.count;
  }
  if (fit.bins.size() < 3) {
    std::ostringstream why;
    why << "only " << fit.bins.size() << " depth bins of " << options_.bin_m << " m with at least "
        << options_.min_bin_samples << " samples (" << total_ << " samples in all); need 3";
    fit.error = why.str();
    return fit;
  }
  fit.min_depth_m = fit.bins.front().depth_m;
  fit.max_depth_m = fit.bins.back().depth_m;
  if (fit.max_depth_m - fit.min_depth_m < kMinDepthSpanM) {
    std::ostringstream why;
    why << "the compared pixels span only " << fit.min_depth_m << ".." << fit.max_depth_m
        << " m of depth; need " << kMinDepthSpanM << " m to tell sigma_per_m2 from sigma_at_0m";
    fit.error = why.str();
    return fit;
  }
  // Weighted least squares of s = a + b x, x = mean d^2, w = n / (1.36 s^2).
  double sw = 0, swx = 0, swy = 0, swxx = 0, swxy = 0;
  for (const DepthBin& bin : fit.bins) {
    const double s = std::max(bin.sigma_mm, 1e-3);
    const double w = static_cast<double>(bin.samples) / (kMadVarianceFactor * s * s);
    sw += w;
    swx += w * bin.depth2_m2;
    swy += w * bin.sigma_mm;
    swxx += w * bin.depth2_m2 * bin.depth2_m2;
    swxy += w * bin.depth2_m2 * bin.sigma_mm;
  }
  const double det = sw * swxx - swx * swx;
  double a = det > 0 ? (swxx * swy - swx * swxy) / det : swy / sw;
  double b = det > 0 ? (sw * swxy - swx * swy) / det : 0;
  if (b < 0) {  // sigma that falls with depth: a constant
    b = 0;
    a = swy / sw;
  } else if (a < 0) {  // through the origin
    a = 0;
    b = swxx > 0 ? swxy / swxx : 0;
  }
  fit.sigma_at_0m_mm = a;
  fit.sigma_per_m2_mm = b;
  for (const DepthBin& bin : fit.bins) {
    // A small edge bin (a few thousand pixels of one odd surface) is
    // reported in the table, not in the summary.
    if (bin.samples * 100 < fit.samples) continue;
    fit.worst_bin_ratio_error =
        std::max(fit.worst_bin_ratio_error, std::abs(bin.sigma_mm / fit.sigma_mm(bin.depth_m) - 1));
  }
  fit.ok = a + b > 0;
  if (!fit.ok) fit.error = "the fitted noise is zero: the camera frames equal the model (a rendered log?)";
  return fit;
}

void SpatialCorrelation::add_frame(const std::vector<float>& z, const std::vector<uint8_t>& valid, int width,
                                   int height) {
  auto clipped = [&](size_t i) { return std::clamp(static_cast<double>(z[i]), -kClipSigmas, kClipSigmas); };
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      if (!valid[i]) continue;
      const double zi = clipped(i);
      for (int lag = 1; lag <= kMaxLag; ++lag) {
        const int neighbours[2] = {u + lag < width ? static_cast<int>(i) + lag : -1,
                                   v + lag < height ? static_cast<int>(i) + lag * width : -1};
        for (int axis = 0; axis < 2; ++axis) {
          const int j = neighbours[axis];
          if (j < 0 || !valid[static_cast<size_t>(j)]) continue;
          const double zj = clipped(static_cast<size_t>(j));
          Sums& s = sums_[axis][lag - 1];
          s.zz += zi * zj;
          s.z1 += zi * zi;
          s.z2 += zj * zj;
          ++s.n;
        }
      }
    }
  }
}

double SpatialCorrelation::rho(int axis, int lag) const {
  const Sums& s = sums_[axis][lag - 1];
  return s.n > 0 && s.z1 > 0 && s.z2 > 0 ? s.zz / std::sqrt(s.z1 * s.z2) : 0.0;
}

double SpatialCorrelation::pixels_per_sample() const {
  double footprint = 1;
  for (int axis = 0; axis < 2; ++axis) {
    double sum = 0;
    for (int lag = 1; lag <= kMaxLag; ++lag) {
      const int64_t n = pairs(axis, lag);
      const double r = rho(axis, lag);
      if (n == 0 || r <= 3.0 / std::sqrt(static_cast<double>(n))) break;
      sum += r;
    }
    footprint *= 1 + 2 * sum;
  }
  return std::max(1.0, footprint);
}

void ScoreStatistics::add(double score, double information) {
  if (!(information > 0) || !std::isfinite(score)) {
    has_previous_ = false;
    return;
  }
  const double t = score / std::sqrt(information);
  ++n_;
  sum_sq_ += t * t;
  max_abs_ = std::max(max_abs_, std::abs(t));
  if (has_previous_) {
    ++differences_;
    difference_sum_sq_ += (t - previous_) * (t - previous_) / 2;
  }
  has_previous_ = true;
  previous_ = t;
}

}  // namespace tofguard::tune
