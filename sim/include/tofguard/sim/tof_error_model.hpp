#pragma once
// The simulated ToF camera's error model: what turns a perfect rendered
// depth image into one that looks like a real time-of-flight camera's.
//
// Input: the renderer's linear Z image in metres (row-major, 0 = nothing in
// range). Per pixel, with r the radial distance along the pixel's ray:
//  1. amplitude A = amplitude_at_1m * cos(incidence) / r^2, the incidence
//     angle from the surface normal estimated from neighbouring pixels;
//  2. mixed pixels: a pixel on a silhouette (a 4-neighbour differs by more
//     than mixed_pixel_jump_m, or sees nothing) sees both surfaces with
//     mixed_pixel_probability; with a random coverage w of its own surface it
//     measures the amplitude-weighted mean distance of the two (a flying
//     pixel between them), or only a weaker return when the other side is
//     empty;
//  3. systematic error e(r) (a polynomial) and Gaussian noise with
//     sigma(r) = sigma0 + k r^2;
//  4. invalid pixels: amplitude below min_valid_amplitude, or dark noise
//     (probability per pixel and frame) -> depth 0.
// Output Z is the measured radial distance times the pixel's Z/r factor.
//
// Deterministic: the output depends only on the input, the config's seed
// and the frame index (each frame has its own random stream, so a dropped
// frame does not change the next one). Every pixel draws the same number of
// random values whatever happens to it, so a change in one part of the
// image does not change the noise elsewhere.
#include <cstdint>
#include <vector>

#include "tofguard/camera/depth_conversion.hpp"
#include "tofguard/settings/sim_settings.hpp"

namespace tofguard::sim {

struct TofImage {
  int width = 0;
  int height = 0;
  // Measured Z along the optical axis, metres; 0 = invalid.
  std::vector<float> depth_m;
  // Amplitude in camera units (0 where nothing returned light).
  std::vector<float> amplitude;
};

class TofErrorModel {
 public:
  TofErrorModel(const SimCameraSettings& config, const Intrinsics& intrinsics);

  // e(r), metres.
  double systematic_error_m(double r_m) const;
  // sigma(r), metres.
  double noise_sigma_m(double r_m) const;

  // Applies the model to `true_depth_m` (intrinsics' width * height Z
  // values in metres, 0 = nothing). Throws std::invalid_argument for a
  // wrong size.
  TofImage apply(const std::vector<float>& true_depth_m, uint64_t frame_index) const;

  const Intrinsics& intrinsics() const { return intrinsics_; }

 private:
  SimCameraSettings config_;
  Intrinsics intrinsics_;
  camera::RadialToZ radial_to_z_;
};

}  // namespace tofguard::sim
