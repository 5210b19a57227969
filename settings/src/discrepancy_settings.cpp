#include "tofguard/settings/discrepancy_settings.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include "tofguard/common/worker_pool.hpp"

namespace tofguard::settings {

int auto_worker_threads() { return std::min(allowed_cpu_count(), kMaxAutoWorkerThreads); }

DiscrepancySettings read_discrepancy_settings(YamlMap map) {
  DiscrepancySettings d;
  {
    YamlMap noise = map.map("noise");
    d.noise_sigma_at_0m_mm = noise.number("sigma_at_0m_mm", 0, 1000);
    d.noise_sigma_per_m2_mm = noise.number("sigma_per_m2_mm", 0, 1000);
    noise.finish();
  }
  d.tolerance_sigmas = map.number("tolerance_sigmas", 0.5, 100);
  d.model_tolerance_mm = map.number("model_tolerance_mm", 0, 1000);
  d.pair_timeout_us = map.milliseconds_as_us("pair_timeout_ms", 1, 10000);
  d.max_pending_frames = static_cast<int>(map.integer("max_pending_frames", 1, 1000));
  d.opening_radius_px = static_cast<int>(map.integer("opening_radius_px", 0, 10));
  d.silhouette_jump_mm = map.number("silhouette_jump_mm", 1, 10000);
  d.near_arm_m = map.number("near_arm_m", 0, 10);
  {
    YamlMap field = map.map("field");
    d.field_range_m = field.number("range_m", 0.01, 20);
    d.field_bin_m = field.number("bin_m", 0.001, 1);
    if (d.field_bin_m > d.field_range_m) field.fail("bin_m", "a bin no wider than range_m");
    if (d.field_range_m / d.field_bin_m > 10000) field.fail("bin_m", "at most 10000 bins up to range_m");
    field.finish();
  }
  d.max_depth_mm = map.number("max_depth_mm", 1, 32767);
  {
    YamlMap colour = map.map("colour_image");
    d.colour_image_enabled = colour.boolean("enabled");
    d.colour_image_channel = colour.string("channel");
    d.colour_image_full_scale_mm = colour.number("full_scale_mm", 1, 32767);
    colour.finish();
  }
  {
    YamlMap evidence = map.map("evidence");
    d.evidence_model_sigma_mm = evidence.number("model_sigma_mm", 0, 1000);
    d.evidence_clip_sigmas = evidence.number("clip_sigmas", 0.5, 100);
    d.evidence_pixels_per_sample = evidence.number("pixels_per_sample", 1, 10000);
    d.evidence_naming_gate_sigmas = evidence.number("naming_gate_sigmas", 1, 100);
    d.evidence_static_bias_mm = evidence.number("static_bias_mm", 0, 1000);
    d.evidence_fixed_pattern_sigma_mm = evidence.number("fixed_pattern_sigma_mm", 0, 1000);
    if (evidence.optional("silhouette_allowance")) {
      YamlMap allowance = evidence.map("silhouette_allowance");
      d.evidence_silhouette_band_px = static_cast<int>(allowance.integer("band_px", 1, 64));
      d.evidence_silhouette_bias_mm = allowance.number("bias_mm", 0, 1000);
      if (allowance.optional("step_mm"))
        d.evidence_silhouette_band_step_mm = allowance.number("step_mm", 1, 1000);
      if (allowance.optional("by_link")) {
        YamlMap by_link = allowance.map("by_link");
        for (const std::string& link : by_link.keys())
          d.evidence_silhouette_bias_by_link_mm[link] = by_link.number(link, 0, 1000);
        by_link.finish();
      }
      allowance.finish();
    }
    if (evidence.optional("max_pixels"))
      d.evidence_max_pixels = static_cast<int>(evidence.integer("max_pixels", 1000, 100000000));
    {
      YamlMap search = evidence.map("search");
      constexpr double kRad = M_PI / 180.0;
      d.evidence_search_range_rad = search.number("range_deg", 0.1, 90) * kRad;
      d.evidence_search_step_rad = search.number("step_deg", 0.01, 10) * kRad;
      d.evidence_search_range_m = search.number("range_mm", 0.1, 1000) / 1000.0;
      d.evidence_search_step_m = search.number("step_mm", 0.01, 100) / 1000.0;
      d.evidence_search_max_points = static_cast<int>(search.integer("max_points", 10, 1000000));
      if (d.evidence_search_step_rad > d.evidence_search_range_rad)
        search.fail("step_deg", "a step no larger than range_deg");
      if (d.evidence_search_step_m > d.evidence_search_range_m)
        search.fail("step_mm", "a step no larger than range_mm");
      search.finish();
    }
    evidence.finish();
  }
  if (map.optional("camera_profile")) {
    d.camera_profile =
        std::make_shared<const CameraProfile>(read_camera_profile(map.existing_path("camera_profile")));
  }
  if (map.optional("worker_threads")) {
    const std::string text = map.string("worker_threads");
    int threads = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), threads);
    if (text == "auto") {
      d.worker_threads = auto_worker_threads();
    } else if (error == std::errc() && end == text.data() + text.size() && threads >= 1 && threads <= 64) {
      d.worker_threads = threads;
    } else {
      map.fail("worker_threads", "an integer in [1, 64] or auto", "'" + text + "'");
    }
  }
  map.finish();
  return d;
}

}  // namespace tofguard::settings
