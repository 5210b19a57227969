#pragma once
// The camera's noise model sigma(d) = a + b d^2 (discrepancy.noise, d the
// camera's depth Z in metres, sigma in millimetres) fitted from the
// discrepancy I_dis = I_gen - I_ToF of nominal frames, and the statistics
// tofguard-tune reports with it (docs/safety-chain.md, "Tuning a new camera:
// tofguard-tune"). Pure computation: no LCM, no rendering.
//
// The fit, robustly:
//  1. the samples (pixels compared, off silhouettes, on a link) go into depth
//     bins of bin_m; each bin keeps a histogram of I_dis in whole millimetres
//     (both depths are whole millimetres);
//  2. per bin with at least min_bin_samples: the median m (a bias, not
//     noise, is removed) and the robust scale s = 1.4826 MAD about it, both
//     from the histogram read as grouped data (each whole millimetre spread
//     uniformly over +-0.5 mm, so that s is not quantised to the
//     millimetre: at sigma 8 mm, MAD 5.4 mm, rounding it would be 10 %);
//  3. a, b by weighted least squares of s on the bin's mean d^2, weight
//     n / s^2 (the variance of 1.4826 MAD is about 1.36 s^2 / n for normal
//     noise), a and b kept >= 0 (the other refitted alone when one comes out
//     negative).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace tofguard::tune {

struct NoiseFitOptions {
  // Width of a depth bin, metres.
  double bin_m = 0.1;
  // A bin with fewer samples is not used.
  int64_t min_bin_samples = 2000;
  // |I_dis| beyond this is counted at it (the medians and MADs of nominal
  // frames are far inside), millimetres.
  int range_mm = 1000;
};

// One depth bin's robust statistics.
struct DepthBin {
  double depth_m = 0;    // mean camera depth of its samples, m
  double depth2_m2 = 0;  // mean d^2, m^2
  int64_t samples = 0;
  double median_mm = 0;  // the bias removed
  double sigma_mm = 0;   // 1.4826 MAD about the median
};

struct NoiseFit {
  bool ok = false;
  std::string error;  // one line when !ok
  double sigma_at_0m_mm = 0;
  double sigma_per_m2_mm = 0;
  // The bins used (at least min_bin_samples each), nearest first.
  std::vector<DepthBin> bins;
  int64_t samples = 0;     // in the bins used
  double min_depth_m = 0;  // the bins' range of mean depths
  double max_depth_m = 0;
  // The largest |s / sigma(d) - 1| over the bins holding at least 1 % of
  // the samples: how well a + b d^2 describes the camera.
  double worst_bin_ratio_error = 0;
  // The median of every bin with samples (index: depth / bin_m), mm: the
  // bias the fit removed there.
  double bin_m = 0.1;
  std::vector<double> bin_median_mm;

  double sigma_mm(double depth_m) const { return sigma_at_0m_mm + sigma_per_m2_mm * depth_m * depth_m; }
  // The bias removed at camera depth `depth_mm` (0 outside the bins), mm.
  double median_mm_at(int depth_mm) const;
};

// Accumulates samples (camera depth, I_dis) per depth bin.
class NoiseSamples {
 public:
  explicit NoiseSamples(const NoiseFitOptions& options = {});

  // One compared pixel: the camera's depth and I_dis, whole millimetres.
  void add(int depth_mm, int dis_mm);

  // The fit over everything added (ok false with the reason when fewer than
  // three bins have min_bin_samples, or they span less than 0.5 m).
  NoiseFit fit() const;
  int64_t total() const { return total_; }

 private:
  struct Bin {
    std::vector<int64_t> histogram;  // I_dis + range_mm
    int64_t count = 0;
    double sum_depth_m = 0;
    double sum_depth2_m2 = 0;
  };
  int bin_of(int depth_mm) const;
  // Median and 1.4826 MAD of a bin, as grouped data.
  void robust(const Bin& bin, double* median_mm, double* sigma_mm) const;

  NoiseFitOptions options_;
  std::vector<Bin> bins_;
  int64_t total_ = 0;
};

// The spatial correlation of standardised residuals z = (I_dis - bin
// median) / sigma(d), clipped to +-4, between pixels k = 1..kMaxLag apart
// along u and along v (both samples). For discrepancy.evidence's
// pixels_per_sample: the number of pixels one independent noise sample
// spreads over.
class SpatialCorrelation {
 public:
  static constexpr int kMaxLag = 4;

  // One frame's standardised residuals, row-major width*height; `valid`
  // (same size) 1 where z is a sample.
  void add_frame(const std::vector<float>& z, const std::vector<uint8_t>& valid, int width, int height);

  // rho along u (axis 0) or v (axis 1) at lag k (1..kMaxLag); 0 without pairs.
  double rho(int axis, int lag) const;
  int64_t pairs(int axis, int lag) const { return sums_[axis][lag - 1].n; }
  // (1 + 2 sum_k rho_u(k)) (1 + 2 sum_k rho_v(k)), each sum over the lags
  // from 1 up to the first whose rho is not above 3 standard errors
  // (1 / sqrt(pairs)): the area of a separable correlation's footprint
  // (3x3 box filter: rho 2/3, 1/3, 0 -> 3 x 3 = 9; independent pixels: 1).
  // At least 1.
  double pixels_per_sample() const;

 private:
  struct Sums {
    double zz = 0, z1 = 0, z2 = 0;
    int64_t n = 0;
  };
  std::array<std::array<Sums, kMaxLag>, 2> sums_{};
};

// The standardised scores t = s / sqrt(I) of one hypothesis parameter over
// frames (the sequential tests take t ~ N(0, 1) without a fault).
class ScoreStatistics {
 public:
  // The next frame's score and information; information <= 0 (not seen)
  // skips the frame and breaks the frame-to-frame chain.
  void add(double score, double information);

  int64_t count() const { return n_; }
  // Mean of t^2 (the variance about 0), and half the mean squared
  // difference of consecutive frames' t (the frame-to-frame part: a bias
  // that changes slowly with the pose cancels in the difference).
  double variance() const { return n_ > 0 ? sum_sq_ / static_cast<double>(n_) : 0; }
  double frame_to_frame_variance() const {
    return differences_ > 0 ? difference_sum_sq_ / static_cast<double>(differences_) : 0;
  }
  int64_t differences() const { return differences_; }
  double max_abs() const { return max_abs_; }

 private:
  int64_t n_ = 0;
  double sum_sq_ = 0;
  int64_t differences_ = 0;
  double difference_sum_sq_ = 0;
  double max_abs_ = 0;
  bool has_previous_ = false;
  double previous_ = 0;
};

}  // namespace tofguard::tune
