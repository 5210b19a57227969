#pragma once
// The embedded default's deployment watched by two cameras, the two-camera
// scene config/sim-two-cameras.yaml: config/sim.yaml's mast camera behind
// the wheelchair and a second simulated imperfect camera ("tof-side") on a
// mast at the wheelchair's left, each commissioned with its own profile
// (docs/camera.md, "The second camera"). For the tests of several cameras.
#include <string>
#include <utility>
#include <vector>

#include "tool_support.hpp"

namespace tofguard::test {

inline std::string two_camera_scene_path() { return source_dir() + "/config/sim-two-cameras.yaml"; }

// sim.yaml's `camera` section (its line to the next top-level key), as text.
inline std::string sim_camera_section(const std::string& sim_yaml) {
  const auto begin = sim_yaml.find("\ncamera:\n");
  const auto end = sim_yaml.find("\nrenderer:\n");
  if (begin == std::string::npos || end == std::string::npos || end < begin) {
    throw std::runtime_error("sim.yaml has no camera section before its renderer section");
  }
  return sim_yaml.substr(begin + 1, end - begin);
}

// The entry of the two-camera scene's `cameras` list with id `id` (from its
// "- id: " line to the next entry or the end of the list), as text.
inline std::string two_camera_scene_entry(const std::string& scene_yaml, const std::string& id) {
  const auto begin = scene_yaml.find("\n- id: " + id + "\n");
  const auto list_end = scene_yaml.find("\nrenderer:\n");
  if (begin == std::string::npos || list_end == std::string::npos || list_end < begin) {
    throw std::runtime_error("sim-two-cameras.yaml has no camera '" + id + "' before its renderer section");
  }
  const auto next = scene_yaml.find("\n- id: ", begin + 1);
  const auto end = next != std::string::npos && next < list_end ? next : list_end;
  std::string entry = scene_yaml.substr(begin + 1, end - begin);
  // The comment lines that introduce the next entry are not this one's.
  while (true) {
    const auto last = entry.rfind('\n', entry.size() - 2);
    if (last == std::string::npos || entry.compare(last + 1, 3, "  #") != 0) break;
    entry.erase(last + 1);
  }
  return entry;
}

// A camera section as an entry of a `cameras` list, with its profile: the
// block sequence sits at the section's own indentation ("- id: ..."), so
// every other line stays as it is.
inline std::string as_camera_list_entry(const std::string& section, const std::string& profile_path) {
  const std::string head = "camera:\n  id: ";
  if (section.compare(0, head.size(), head) != 0)
    throw std::runtime_error("not a camera section: " + section);
  std::string entry = "- id: " + section.substr(head.size());
  while (entry.size() > 1 && entry[entry.size() - 2] == '\n') entry.pop_back();  // its blank lines
  return entry + "  camera_profile: " + profile_path + "\n";
}

// The side camera as a lone `camera` section (without its profile line).
inline std::string side_camera_section(const std::string& scene_yaml) {
  std::string entry = two_camera_scene_entry(scene_yaml, "tof-side");
  entry.erase(entry.find(config_line(entry, "  camera_profile: ")), std::string::npos);
  return "camera:\n  id: " + entry.substr(std::string("- id: ").size()) + "\n";
}

// config/sim-two-cameras.yaml with `replacements` and `appended` as
// sim_config_variant applies them; written to output_dir()/<name>.yaml.
inline std::string two_camera_config(
    const std::string& name, const std::vector<std::pair<std::string, std::string>>& replacements = {},
    const std::string& appended = "") {
  return config_variant(two_camera_scene_path(), name, replacements, appended);
}

// config/sim.yaml with the side camera in place of its mast camera, alone
// (a one-camera deployment seeing what tof-side sees), with its profile;
// written to output_dir()/<name>.yaml.
inline std::string side_camera_alone_config(const std::string& name) {
  const std::string sim_yaml = read_file(source_dir() + "/config/sim.yaml");
  return sim_config_variant(
      name, {{sim_camera_section(sim_yaml), side_camera_section(read_file(two_camera_scene_path()))},
             {config_line(sim_yaml, "  camera_profile: "),
              "  camera_profile: " + source_dir() + "/config/sim-side-camera-profile.yaml\n"}});
}

}  // namespace tofguard::test
