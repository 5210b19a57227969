#pragma once
// The embedded default's deployment (config/sim.yaml) watched by two
// cameras: its mast camera behind the wheelchair and a second simulated
// imperfect camera on the wheelchair's other side, each commissioned with
// its own profile. For the tests of several cameras.
//
// The second camera ("tof-side"): 2.0 m up a mast at the wheelchair's left
// (world frame: x forward, y left, z up; the wheelchair's centre is at
// x = -0.25 m, y = 0), looking down and right across the user's lap at the
// arm's workspace (its optical axis through (0.25, -0.35, 1.00) m). It sees
// the arm from the side the mast camera does not, the table, the floor and
// the user's legs and left side. Its imperfections are
// sim::draw_imperfect_camera(8) (a smooth error of up to 15 mm over 1-3 m,
// fixed pattern 2.6 mm, -2.9 mm per decade of amplitude, multipath up to
// 12 mm, a 7.1 mm warm-up drift); its profile, config/sim-side-camera-
// profile.yaml, was commissioned as the mast camera's (docs/camera.md,
// "The second camera").
#include <string>
#include <utility>
#include <vector>

#include "tool_support.hpp"

namespace tofguard::test {

// sim.yaml's `camera` section (its line to the next top-level key), as text.
inline std::string sim_camera_section(const std::string& sim_yaml) {
  const auto begin = sim_yaml.find("\ncamera:\n");
  const auto end = sim_yaml.find("\nrenderer:\n");
  if (begin == std::string::npos || end == std::string::npos || end < begin) {
    throw std::runtime_error("sim.yaml has no camera section before its renderer section");
  }
  return sim_yaml.substr(begin + 1, end - begin);
}

inline std::string replaced_once(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos)
    throw std::runtime_error("sim.yaml's camera section no longer contains: " + from);
  return text.replace(at, from.size(), to);
}

// The side camera as sim.yaml's camera section: the mast camera's sensor
// (intrinsics, rate, distance calibration, noise) at its own place, with
// its own noise seed and imperfections, without a profile line.
inline std::string side_camera_section(const std::string& sim_yaml) {
  std::string s = sim_camera_section(sim_yaml);
  s = replaced_once(s, "  id: tof-mast\n", "  id: tof-side\n");
  s = replaced_once(s, "    translation_m: [-0.90, -0.20, 1.80]\n",
                    "    translation_m: [-0.10, 0.70, 2.00]\n");
  s = replaced_once(s, config_line(s, "    rotation_wxyz: "),
                    "    rotation_wxyz: [0.065026738, -0.146389461, 0.902092505, -0.400712817]\n");
  s = replaced_once(s, "    seed: 1\n", "    seed: 2\n");
  s = replaced_once(
      s, config_line(s, "    residual: {"),
      "    residual: {wiggle_amplitude_mm: 14.683, wiggle_period_m: 2.8352, wiggle_phase_rad: 5.4181,\n"
      "      slope_mm_per_m: 3.6004, pixel_offset_sigma_mm: 2.6045, reflectivity_bias_mm_per_decade: "
      "-2.9219,\n"
      "      reference_amplitude: 4000, multipath_max_mm: 11.946, warmup_drift_mm: 7.1233,\n"
      "      warmup_time_constant_s: 352.78, on_before_start_s: 1200}\n");
  return s;
}

// A camera section as an entry of a `cameras` list, with its profile: the
// block sequence sits at the section's own indentation ("- id: ..."), so
// every other line stays as it is.
inline std::string as_camera_list_entry(const std::string& section, const std::string& profile_path) {
  std::string entry = replaced_once(section, "camera:\n  id: ", "- id: ");
  return entry + "  camera_profile: " + profile_path + "\n";
}

// config/sim.yaml with `cameras: [tof-mast, tof-side]` instead of its lone
// camera (each with its own profile), then `replacements` and `appended`
// as sim_config_variant applies them; written to output_dir()/<name>.yaml.
inline std::string two_camera_config(const std::string& name,
                                     std::vector<std::pair<std::string, std::string>> replacements = {},
                                     const std::string& appended = "") {
  const std::string sim_yaml = read_file(source_dir() + "/config/sim.yaml");
  const std::string config_dir = source_dir() + "/config/";
  const std::string mast = sim_camera_section(sim_yaml);
  const std::string cameras =
      "cameras:\n" + as_camera_list_entry(mast, config_dir + "sim-camera-profile.yaml") +
      as_camera_list_entry(side_camera_section(sim_yaml), config_dir + "sim-side-camera-profile.yaml");
  replacements.insert(replacements.begin(),
                      {{mast, cameras}, {config_line(sim_yaml, "  camera_profile: "), ""}});
  return sim_config_variant(name, replacements, appended);
}

// config/sim.yaml with the side camera in place of its mast camera, alone
// (a one-camera deployment seeing what tof-side sees), with its profile;
// written to output_dir()/<name>.yaml.
inline std::string side_camera_alone_config(const std::string& name) {
  const std::string sim_yaml = read_file(source_dir() + "/config/sim.yaml");
  return sim_config_variant(
      name, {{sim_camera_section(sim_yaml), side_camera_section(sim_yaml)},
             {config_line(sim_yaml, "  camera_profile: "),
              "  camera_profile: " + source_dir() + "/config/sim-side-camera-profile.yaml\n"}});
}

}  // namespace tofguard::test
