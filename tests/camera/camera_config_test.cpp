// The camera's config keys (camera.depth_calibration, camera.uvc,
// camera.sim): strict, range-checked, one-line errors.
#include <gtest/gtest.h>

#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tool_support.hpp"

namespace tofguard {
namespace {

std::string variant(const std::string& name, const std::string& replace = "", const std::string& with = "") {
  if (replace.empty()) return test::sim_config_variant(name);
  return test::sim_config_variant(name, {{replace, with}});
}

std::string error_of(const std::string& path) {
  try {
    deployment::load_config(path, nullptr);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(CameraSettings, EmbeddedDefaultHasTheSimCamera) {
  const deployment::Config c = deployment::load_config(test::source_dir() + "/config/sim.yaml", nullptr);
  EXPECT_EQ(c.camera.source, "sim");
  EXPECT_EQ(c.camera.sim.systematic_error_m.size(), 6u);
  EXPECT_DOUBLE_EQ(c.camera.sim.noise_sigma0_mm, 4.75);
  EXPECT_TRUE(c.camera.depth_calibration.enabled);
  EXPECT_EQ(c.camera.depth_calibration.degree, 7);
  EXPECT_EQ(c.camera.depth_calibration.coefficients_m.size(), 8u);
}

TEST(CameraSettings, UvcSection) {
  const deployment::Config c = deployment::load_config(
      variant("uvc_ok", "source: sim",
              "source: uvc\n  uvc: {vendor_id: \"2bc5\", product_id: \"0401\", serial: \"A1\", "
              "format: z16, depth_unit_mm: 0.125, distance: radial}"),
      nullptr);
  EXPECT_EQ(c.camera.uvc.vendor_id, 0x2bc5);
  EXPECT_EQ(c.camera.uvc.product_id, 0x0401);
  EXPECT_EQ(c.camera.uvc.serial, "A1");
  EXPECT_EQ(c.camera.uvc.format, "z16");
  EXPECT_DOUBLE_EQ(c.camera.uvc.depth_unit_mm, 0.125);
  EXPECT_TRUE(c.camera.uvc.radial_distance);
}

TEST(CameraSettings, RejectsBadCameraKeys) {
  EXPECT_NE(error_of(variant("uvc_missing", "source: sim", "source: uvc"))
                .find("camera.uvc: missing key, expected a mapping"),
            std::string::npos);
  const std::string bad_id =
      error_of(variant("uvc_bad_id", "source: sim",
                       "source: uvc\n  uvc: {vendor_id: 11205, product_id: \"0401\", format: z16, "
                       "depth_unit_mm: 1, distance: z}"));
  EXPECT_NE(bad_id.find("camera.uvc.vendor_id: expected a USB id as 4 hex digits"), std::string::npos)
      << bad_id;
  const std::string unknown = error_of(variant("sim_unknown", "    seed: 1", "    seed: 1\n    sead: 2"));
  EXPECT_NE(unknown.find("camera.sim.sead"), std::string::npos) << unknown;
  const std::string range =
      error_of(variant("sim_range", "dark_pixel_probability: 0.002", "dark_pixel_probability: 2"));
  EXPECT_NE(range.find("camera.sim.amplitude.dark_pixel_probability: expected a number in [0, 1]"),
            std::string::npos)
      << range;
  const std::string degree = error_of(variant("cal_degree", "    degree: 7", "    degree: 6"));
  EXPECT_NE(degree.find("camera.depth_calibration.coefficients_m: expected a list of 7 numbers"),
            std::string::npos)
      << degree;
  const std::string fault =
      error_of(variant("fault_kind", "faults: []", "faults: [{kind: melt, start_s: 1, duration_s: 1}]"));
  EXPECT_NE(fault.find("camera.sim.faults[0].kind"), std::string::npos) << fault;
}

TEST(CameraSettings, Faults) {
  const deployment::Config c = deployment::load_config(
      variant("faults_ok", "faults: []",
              "faults:\n"
              "      - {kind: pose_drift, start_s: 2, duration_s: 3, translation_m_per_s: [0.01, 0, "
              "0], rotation_rad_per_s: [0, 0.02, 0]}\n"
              "      - {kind: intruding_object, start_s: 1, duration_s: 2, size_m: [0.1, 0.1, 0.5], "
              "position_m: [0.5, 0, 1]}\n"),
      nullptr);
  ASSERT_EQ(c.camera.sim.faults.size(), 2u);
  EXPECT_EQ(c.camera.sim.faults[0].kind, "pose_drift");
  EXPECT_DOUBLE_EQ(c.camera.sim.faults[0].drift_rotation_rad_per_s.y(), 0.02);
  EXPECT_DOUBLE_EQ(c.camera.sim.faults[1].object_size_m.z(), 0.5);
  EXPECT_TRUE(c.camera.sim.faults[1].object_velocity_m_per_s.isZero());
}

}  // namespace
}  // namespace tofguard
