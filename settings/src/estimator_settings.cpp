#include "tofguard/settings/estimator_settings.hpp"

namespace tofguard::settings {

EstimatorSettings read_estimator_settings(YamlMap map) {
  EstimatorSettings e;
  e.estimate_joints = map.boolean("estimate_joints");
  e.estimate_camera = map.boolean("estimate_camera");
  {
    YamlMap warning = map.map("warning");
    e.warning_mismatch_fraction = warning.number("mismatch_fraction", 0, 1);
    e.warning_p95_abs_dis_mm = warning.number("p95_abs_dis_mm", 0, 32767);
    e.warning_min_interval_us = warning.milliseconds_as_us("min_interval_ms", 0, 60000);
    warning.finish();
  }
  e.periodic_period_us = map.milliseconds_as_us("periodic_period_ms", 10, 3600000);
  e.max_pending_frames = static_cast<int>(map.integer("max_pending_frames", 1, 100));
  e.frames_per_estimate = static_cast<int>(map.integer("frames_per_estimate", 1, e.max_pending_frames));
  e.max_iterations = static_cast<int>(map.integer("max_iterations", 1, 100));
  e.pixel_stride = static_cast<int>(map.integer("pixel_stride", 1, 8));
  map.finish();
  return e;
}

}  // namespace tofguard::settings
