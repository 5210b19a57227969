#pragma once
// The simulated camera's settings used by the camera tests: the embedded
// default's 176x144 camera and an error model like config/sim.yaml's.
#include "tofguard/common/camera_settings.hpp"
#include "tofguard/settings/sim_settings.hpp"

namespace tofguard::sim::sim_test {

inline Intrinsics test_intrinsics() {
  Intrinsics in;
  in.width = 176;
  in.height = 144;
  in.fx = 221.0;
  in.fy = 220.5;
  in.cx = 87.3;
  in.cy = 71.8;
  return in;
}

// A known 5th-order systematic error: 58..148 mm over 0.5..5 m.
inline std::vector<double> test_systematic_error_m() {
  return {0.0186286, 0.388128, -0.376992, 0.131278, -0.0179423, 0.000764776};
}

inline SimCameraSettings test_sim_config() {
  SimCameraSettings c;
  c.seed = 1;
  c.systematic_error_m = test_systematic_error_m();
  c.noise_sigma0_mm = 4.75;        // 5 mm at 0.5 m
  c.noise_sigma_per_m2_mm = 1.01;  // 30 mm at 5 m
  c.amplitude_at_1m = 4000;
  c.min_valid_amplitude = 60;
  c.dark_pixel_probability = 0.0;
  c.mixed_pixel_jump_m = 0.05;
  c.mixed_pixel_probability = 0.7;
  return c;
}

}  // namespace tofguard::sim::sim_test
