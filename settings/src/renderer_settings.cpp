#include "tofguard/settings/renderer_settings.hpp"

namespace tofguard::settings {

RendererSettings read_renderer_settings(YamlMap renderer) {
  RendererSettings r;
  r.geometry = renderer.choice("geometry", {"visual", "collision"});
  r.padding_m = renderer.number("padding_m", 0, 1);
  // Optional: a config written before meshes were simplified keeps the
  // exact meshes it was checked with.
  r.simplify_error_mm = renderer.optional_number("simplify_error_mm", 0, 0, 10);
  r.near_m = renderer.number("near_m", 1e-3, 100);
  r.far_m = renderer.number("far_m", 1e-3, 1000);
  if (r.far_m <= r.near_m) {
    renderer.fail("far_m", "a distance greater than near_m", std::to_string(r.far_m));
  }
  r.arm_cover_cell_m = renderer.number("arm_cover_cell_m", 0.005, 0.5);
  r.max_extrapolation_us = renderer.milliseconds_as_us("max_extrapolation_ms", 0, 1000);
  {
    YamlMap poses = renderer.map("camera_pose");
    r.camera_pose_history_us = poses.milliseconds_as_us("history_ms", 10, 60000);
    r.camera_pose_max_extrapolation_us = poses.milliseconds_as_us("max_extrapolation_ms", 0, 1000);
    r.camera_pose_max_gap_us = poses.milliseconds_as_us("max_gap_ms", 1, 10000);
    poses.finish();
  }
  {
    YamlMap prediction = renderer.map("prediction");
    r.prediction_enabled = prediction.boolean("enabled");
    // Optional, so that configs written before it keep their meaning.
    r.prediction_from_joint_states =
        prediction.optional("from_joint_states") && prediction.boolean("from_joint_states");
    r.prediction_joint_tolerance_deg = prediction.number("joint_tolerance_deg", 0, 10);
    r.prediction_joint_tolerance_m = prediction.number("joint_tolerance_m", 0, 1);
    r.prediction_pose_tolerance_mm = prediction.number("pose_tolerance_mm", 0, 100);
    r.prediction_pose_tolerance_deg = prediction.number("pose_tolerance_deg", 0, 10);
    prediction.finish();
  }
  renderer.finish();
  return r;
}

}  // namespace tofguard::settings
