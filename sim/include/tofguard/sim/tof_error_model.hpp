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
//  4. residual errors (camera.sim.residual, SimResidualSettings), what a
//     real camera still gets wrong after its distance calibration removed
//     e(r); each adds to the measured r:
//     - wiggle and slope, smooth in r: a sin(2 pi r / period + phase) + s r;
//     - a fixed per-pixel offset (fixed-pattern noise): drawn once, from the
//       seed's own stream, when the model is made; the same in every frame;
//     - an amplitude bias k * log10(A / A_ref), A the pixel's amplitude after
//       mixing: a dark (or far, or oblique) surface reads differently from
//       a bright one by k millimetres per decade of amplitude;
//     - multipath, a cheap deterministic approximation (below);
//     - common-mode warm-up drift d * (1 - exp(-t / tau)), t the time since
//       the camera started;
//  5. invalid pixels: amplitude below min_valid_amplitude, or dark noise
//     (probability per pixel and frame) -> depth 0.
// Output Z is the measured radial distance times the pixel's Z/r factor.
//
// Multipath, approximated: a real camera's pixel also receives light that
// went from the camera to another surface and from there to the pixel's
// surface (a longer path), so it reads farther; the effect is large in
// concave corners (a link in front of a wall, a table's edge against the
// wall). Here, from the true image only: pixel i gets
//   multipath_max * min(1, 2 * F),
//   F = (1 / N) * sum over the other N pixels j of the 9x9 window around i
//       with r_j > r_i + 1 cm and |p_j - p_i| <= 0.5 m of max(0, n_j . e_ji),
// p the seen points, n_j the unit normal at j (towards the camera), e_ji
// the unit vector from p_j to p_i: the share of the window that is farther
// surface facing the pixel. A pixel with half its window such a surface (at
// a corner's edge) gets the maximum; a flat surface, a convex edge and a
// pixel whose surroundings are nearer get nothing. Limits: the window is
// fixed in pixels, not metres (a far corner's multipath reaches further
// over the surface than a near one's); it ignores the intensity of the
// other surface's light (distance, albedo), occlusion between the two
// surfaces and light from outside the window or the image; it does not
// mix a second return into the amplitude. It is a plausible, bounded
// bias in the right places, not an optical simulation. Cost, 176x144 on
// one core of the 2-core VM: +3 ms per frame for a box before a wall, +8 ms
// for a floor receding over the whole image (where most neighbours are
// farther); nothing with multipath_max_mm 0.
//
// Deterministic: the output depends only on the input, the config's seed,
// the frame index and the time since start (each frame has its own random
// stream, so a dropped frame does not change the next one). Every pixel
// draws the same number of random values whatever happens to it, so a
// change in one part of the image does not change the noise elsewhere; the
// residual errors draw nothing per frame, so they leave the noise as it is.
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
  // The residual's wiggle and slope at radial distance r, metres.
  double wiggle_error_m(double r_m) const;
  // The residual's amplitude bias for a pixel of amplitude `amplitude`
  // (camera units; below 1 counts as 1), metres.
  double amplitude_bias_m(double amplitude) const;
  // The residual's warm-up drift `time_since_start_s` seconds after the
  // camera started, metres.
  double warmup_drift_m(double time_since_start_s) const;
  // The fixed offset of pixel (u, v), metres (0 without fixed-pattern noise).
  double pixel_offset_m(int u, int v) const;

  // Applies the model to `true_depth_m` (intrinsics' width * height Z
  // values in metres, 0 = nothing) for frame `frame_index` (selects the
  // noise) captured `time_since_start_s` seconds after the camera started
  // (the warm-up drift). Throws std::invalid_argument for a wrong size.
  TofImage apply(const std::vector<float>& true_depth_m, uint64_t frame_index,
                 double time_since_start_s) const;

  const Intrinsics& intrinsics() const { return intrinsics_; }

 private:
  SimCameraSettings config_;
  Intrinsics intrinsics_;
  camera::RadialToZ radial_to_z_;
  // Fixed-pattern noise per pixel (row-major), metres; empty without it.
  std::vector<float> pixel_offsets_m_;
};

// A random imperfect camera for tests and tools, uniformly within what real
// ToF cameras show after calibration: wiggle 5-25 mm with a period of 1-3 m
// and a phase in [0, 2 pi), slope -5..5 mm/m, pixel offsets sigma 2-5 mm,
// amplitude bias 1-4 mm per decade of either sign, multipath up to 5-20 mm,
// warm-up drift 3-8 mm with a time constant of 3-8 min. The same seed gives
// the same camera. `reference_amplitude`: the amplitude that reads without
// bias (e.g. the camera's amplitude.at_1m), camera units.
SimResidualSettings draw_imperfect_camera(uint64_t seed, double reference_amplitude);

}  // namespace tofguard::sim
