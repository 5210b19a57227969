#pragma once
// The camera's noise model, one place for every stage that weighs a depth
// by its noise: the discrepancy's pixel tolerance and evidence weights
// (discrepancy/) and the motion estimator's residual weights (estimator/).
// Configured as discrepancy.noise.{sigma_at_0m_mm, sigma_per_m2_mm}
// (docs/safety-chain.md); tofguard-tune fits it from a recording.
//
//   sigma(d) = sigma_at_0m_mm + sigma_per_m2_mm * d^2,  d the camera depth in metres.
//
// Kept in millimetres, as the config states it; sigma_m() is the same
// figure in metres for the maths that works in metres.
#include "tofguard/common/depth_frame.hpp"

namespace tofguard {

struct DepthNoise {
  double sigma_at_0m_mm = 4.0;
  double sigma_per_m2_mm = 1.2;

  // sigma at camera depth `depth_mm`, millimetres.
  double sigma_mm(double depth_mm) const {
    const double d_m = metres_from_mm(depth_mm);
    return sigma_at_0m_mm + sigma_per_m2_mm * d_m * d_m;
  }
  // sigma at camera depth `depth_m`, metres.
  double sigma_m(double depth_m) const {
    return metres_from_mm(sigma_at_0m_mm + sigma_per_m2_mm * depth_m * depth_m);
  }
};

}  // namespace tofguard
