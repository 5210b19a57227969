#pragma once
// The error of the arm's pixels on the near side of a rendered step, beyond
// the smooth part (the evidence's silhouette allowance, docs/safety-chain.md
// "Static error: the composite null"): a ToF camera's multipath, a link
// read farther before the surface behind it. It moves with the arm, so no
// per-pixel profile learns it, and it changes with the pose (what lies
// behind the link, how near).
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "tofguard/tune/noise_fit.hpp"
#include "tofguard/tune/rendered_pair.hpp"

namespace tofguard::tune {

// Rings of distance 1..kStepRingsPx pixels (Chebyshev) from the nearest
// rendered surface farther by more than a class's step; a ring of a
// link, or a second of a link's band, counts with at least
// kMinStepRingSamples pixels.
constexpr int kStepRingsPx = 12;
constexpr int64_t kMinStepRingSamples = 200;
// The rendered step that opens the band (EvidenceOptions::
// silhouette_band_step_mm), mm. Multipath needs a surface behind the
// pixel, not a silhouette: the arm's own concave corners (a wrist before
// its forearm, a gripper before its wrist) are steps of 1-5 cm, under the
// 5 cm silhouette jump, and a simulated camera's multipath there stopped
// the Kinova Gen3 on joint_6 (docs/safety-chain.md, "Static error: the
// composite null"). 1 cm: about twice a ToF camera's depth sigma at 1 m
// (4-6 mm), a step a frame's pixels show as a surface behind rather than
// noise on a slope. A smaller step widens the band over the arm's slopes
// and costs detection. The simulated camera's multipath starts at 1 cm
// steps too (sim/tof_error_model.cpp); a real camera's behind smaller
// steps is left to static_bias_mm. Measured as one class with the
// silhouettes, the corners' many pixels lowered a link's mean beside its
// silhouette, and the iiwa14 stopped on joint 6 (its links' allowances
// 0.2-2.2 mm within 7 px, from the silhouettes alone 1.0-2.0 mm within
// 12 px): each class is measured on its own, and a link takes the larger.
constexpr double kBandStepMm = 10;

// Measured on each of the arm's links, its pixels used as the noise fit's
// (noise_pixels) and within the naming gate of the smooth fit's sigma: e =
// I_dis less the smooth part at the pixel's rendered depth, mm.
struct NearStepError {
  // Per ring of the silhouettes: the largest |mean e| of a link and its
  // samples.
  std::vector<double> ring_mean_mm;
  std::vector<int64_t> ring_samples;
  // The band: the farthest ring of either class whose |mean| + 2 standard
  // errors exceeds the smooth allowance on some link; 0: none (and no
  // allowance).
  int band_px = 0;
  // The rendered step the band opens at (mm), and the two classes of its
  // pixels, each measured on its own (a class's rings and one-second means
  // would be diluted by the other's pixels): the near side of silhouettes
  // (a step over the silhouette jump within kStepRingsPx; ring_* are
  // theirs) and the arm's concave corners (a step over band_step_mm, no
  // silhouette within kStepRingsPx). band_px and bias_by_link_mm are the
  // larger of the two.
  double band_step_mm = 0;
  int silhouette_band_px = 0;
  int corner_band_px = 0;
  double corner_bias_mm = 0;
  // Each measured link's allowance beyond the smooth one: the larger of its
  // rings' bounds (|mean| + 2 standard errors) and its largest |mean e|
  // within the band over any one second of the recording, less the smooth
  // allowance, >= 0. A link without a ring of kMinStepRingSamples is not
  // measured (it takes bias_mm). The whole recording's mean averages poses
  // whose multipath differs in size and sign; a CUSUM needs a bias held for
  // only a few seconds to reach h.
  std::map<std::string, double> bias_by_link_mm;
  // The largest of them and its link.
  double bias_mm = 0;
  std::string link;
};

// `frames` in recording order (each frame's second: its camera utime less
// the first's); `silhouette_jump_mm`: the silhouettes left out of the
// noise pixels; `band_step_mm`: the rendered step the rings are measured
// from; `smooth`: the fit whose median by depth is the smooth part;
// `smooth_allowance_mm`: the evidence's static_bias_mm.
NearStepError measure_near_step_error(const std::vector<RenderedPair>& frames, double silhouette_jump_mm,
                                      double band_step_mm, double naming_gate_sigmas, const NoiseFit& smooth,
                                      double smooth_allowance_mm);

}  // namespace tofguard::tune
