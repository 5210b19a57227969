// The two-camera scene (config/sim-two-cameras.yaml) is the embedded default
// (config/sim.yaml) with a second camera: every top-level section but the
// cameras, the launched processes and the lone camera's profile line is
// sim.yaml's, line for line, so that a change to the default that is not
// made to the scene fails here; its first camera is sim.yaml's camera; it
// loads with two cameras, each with its own profile; and it launches each
// camera's processes once per camera.
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "tofguard/common/process.hpp"
#include "tofguard/deployment/config.hpp"
#include "two_camera_config.hpp"

namespace tofguard::test {
namespace {

// A config's top-level sections by key, each with the comment lines right
// above its key line (no blank line between) and up to the next such block.
std::map<std::string, std::string> top_level_sections(const std::string& text,
                                                      std::vector<std::string>* order) {
  std::vector<std::string> lines;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line + "\n");
  std::vector<size_t> starts;
  std::vector<std::string> keys;
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    if (l.empty() || l[0] == ' ' || l[0] == '#' || l[0] == '\n' || l[0] == '-') continue;
    size_t start = i;
    while (start > 0 && lines[start - 1][0] == '#') --start;
    starts.push_back(start);
    keys.push_back(l.substr(0, l.find(':')));
  }
  std::map<std::string, std::string> sections;
  for (size_t k = 0; k < starts.size(); ++k) {
    const size_t end = k + 1 < starts.size() ? starts[k + 1] : lines.size();
    std::string section;
    for (size_t i = starts[k]; i < end; ++i) section += lines[i];
    sections[keys[k]] = section;
  }
  *order = keys;
  return sections;
}

// `section` without the line starting with `prefix` and the comment lines
// right above it.
std::string without_line_and_its_comment(const std::string& section, const std::string& prefix) {
  const std::string line = config_line(section, prefix);
  size_t at = section.find(line);
  size_t begin = at;
  while (begin > 0) {
    const size_t previous = section.rfind('\n', begin - 2);
    const size_t line_start = previous == std::string::npos ? 0 : previous + 1;
    if (section.compare(line_start, 3, "  #") != 0) break;
    begin = line_start;
  }
  return section.substr(0, begin) + section.substr(at + line.size());
}

TEST(TwoCameraScene, EverySectionButTheCamerasAndTheLaunchIsSimYamls) {
  const std::string sim_yaml = read_file(source_dir() + "/config/sim.yaml");
  const std::string scene_yaml = read_file(two_camera_scene_path());
  std::vector<std::string> sim_order, scene_order;
  const auto sim = top_level_sections(sim_yaml, &sim_order);
  const auto scene = top_level_sections(scene_yaml, &scene_order);
  std::vector<std::string> expected_order = sim_order;
  std::replace(expected_order.begin(), expected_order.end(), std::string("camera"), std::string("cameras"));
  EXPECT_EQ(scene_order, expected_order);
  for (const auto& [key, section] : sim) {
    if (key == "camera" || key == "launch") continue;
    ASSERT_TRUE(scene.count(key)) << "sim-two-cameras.yaml has no " << key << " section";
    const std::string expected =
        key == "discrepancy" ? without_line_and_its_comment(section, "  camera_profile: ") : section;
    EXPECT_EQ(scene.at(key), expected)
        << "sim-two-cameras.yaml's " << key << " section is not sim.yaml's: change both";
  }
  // Its first camera is sim.yaml's, with sim.yaml's profile.
  const std::string profile = config_line(sim_yaml, "  camera_profile: ");
  EXPECT_EQ(
      two_camera_scene_entry(scene_yaml, "tof-mast"),
      as_camera_list_entry(sim_camera_section(sim_yaml),
                           profile.substr(profile.find(": ") + 2, profile.size() - profile.find(": ") - 3)));
}

TEST(TwoCameraScene, LoadsWithTwoCamerasEachWithItsOwnProfile) {
  const deployment::Config config = deployment::load_config(two_camera_scene_path(), nullptr);
  ASSERT_EQ(config.cameras.size(), 2u);
  std::set<std::string> profiles;
  for (const deployment::CameraSection& camera : config.cameras) {
    ASSERT_TRUE(camera.profile) << camera.id;
    EXPECT_EQ(camera.profile->camera_id, camera.id);
    profiles.insert(camera.profile->measured_on);
  }
  EXPECT_EQ(config.cameras[0].id, "tof-mast");
  EXPECT_EQ(config.cameras[1].id, "tof-side");
  EXPECT_EQ(profiles.size(), 2u) << "both cameras name the same profile";
  EXPECT_NE(config.cameras[0].pose.frame_from_optical().translation(),
            config.cameras[1].pose.frame_from_optical().translation());
}

// Each process of one camera (per_camera_process_names) that sim.yaml
// launches is launched once per camera with --camera ID; every other
// process once, as in sim.yaml.
TEST(TwoCameraScene, LaunchesEachCamerasProcessesOncePerCamera) {
  const std::regex process_line(
      R"(\n    - \{name: ([^,]+), command: \[([a-z-]+), --config, "\{config\}"(, --camera, ([a-z-]+))?(, --task)?\], required: (true|false)\})");
  auto launched = [&](const std::string& path) {
    const std::string text = read_file(path);
    std::multiset<std::string> commands;
    for (std::sregex_iterator it(text.begin(), text.end(), process_line), end; it != end; ++it) {
      commands.insert((*it)[2].str() + " " + (*it)[4].str() + " required " + (*it)[6].str());
    }
    return commands;
  };
  const std::multiset<std::string> sim = launched(source_dir() + "/config/sim.yaml");
  ASSERT_GE(sim.size(), 6u);
  std::multiset<std::string> expected;
  const std::vector<std::string>& per_camera = per_camera_process_names();
  for (const std::string& command : sim) {
    const std::string program = command.substr(0, command.find(' '));
    const std::string required = command.substr(command.find(" required"));
    if (std::find(per_camera.begin(), per_camera.end(), program) == per_camera.end()) {
      expected.insert(command);
      continue;
    }
    for (const std::string id : {"tof-mast", "tof-side"}) expected.insert(program + " " + id + required);
  }
  EXPECT_EQ(launched(two_camera_scene_path()), expected);
}

}  // namespace
}  // namespace tofguard::test
