#pragma once
// The camera tofguard-tune's tests tune: config/sim.yaml's simulated camera
// made ideal (ideal_camera_replacements), with noise the default config has
// never seen, sigma(r) = 8 mm + 2.0 mm/m^2 r^2 along the ray (the
// default's: 4.75 + 1.01 r^2), at 25 Hz (30). discrepancy.noise stays the
// ideal camera's (4 + 1.2 d^2): what tofguard-tune replaces.
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tofguard/settings/sim_settings.hpp"

#include "tool_support.hpp"

namespace tofguard::test {

inline constexpr double kUnseenSigma0Mm = 8.0;
inline constexpr double kUnseenSigmaPerM2Mm = 2.0;
inline constexpr double kUnseenRateHz = 25;

// The recordings these configs make (write_nominal_log: the in-process
// simulated camera) show no wheelchair user, so the chain they are tuned
// and replayed with models none.
inline const std::string kNoUser = "occupant: ~\n";

// The config's path (output_dir()/<name>.yaml).
inline std::string unseen_camera_config(const std::string& name) {
  std::vector<std::pair<std::string, std::string>> replacements = ideal_camera_replacements();
  replacements.push_back(
      {"noise: {sigma0_mm: 4.75, sigma_per_m2_mm: 1.01}", "noise: {sigma0_mm: 8.0, sigma_per_m2_mm: 2.0}"});
  replacements.push_back({"  rate_hz: 30\n", "  rate_hz: 25\n"});
  return sim_config_variant(name, replacements, kNoUser);
}

// unseen_camera_config's camera with the static errors `residual` (the
// simulator's camera.sim.residual; the config's discrepancy section does not
// know them).
inline std::string imperfect_camera_config(const std::string& name,
                                           const sim::SimResidualSettings& residual) {
  std::ostringstream map;
  map.precision(10);
  map << "    residual: {wiggle_amplitude_mm: " << residual.wiggle_amplitude_mm
      << ", wiggle_period_m: " << residual.wiggle_period_m
      << ", wiggle_phase_rad: " << residual.wiggle_phase_rad
      << ", slope_mm_per_m: " << residual.slope_mm_per_m
      << ", pixel_offset_sigma_mm: " << residual.pixel_offset_sigma_mm
      << ", reflectivity_bias_mm_per_decade: " << residual.reflectivity_bias_mm_per_decade
      << ", reference_amplitude: " << residual.reference_amplitude
      << ", multipath_max_mm: " << residual.multipath_max_mm
      << ", warmup_drift_mm: " << residual.warmup_drift_mm
      << ", warmup_time_constant_s: " << residual.warmup_time_constant_s << "}\n";
  std::vector<std::pair<std::string, std::string>> replacements = ideal_camera_replacements();
  replacements.push_back(
      {"noise: {sigma0_mm: 4.75, sigma_per_m2_mm: 1.01}", "noise: {sigma0_mm: 8.0, sigma_per_m2_mm: 2.0}"});
  replacements.push_back({"  rate_hz: 30\n", "  rate_hz: 25\n"});
  replacements.push_back({"    faults: []\n", map.str() + "    faults: []\n"});
  return sim_config_variant(name, replacements, kNoUser);
}

}  // namespace tofguard::test
