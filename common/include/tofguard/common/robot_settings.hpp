#pragma once
// The robot model and the static environment (config sections `robot` and
// `environment`): what the renderer, the risk classifier, the estimator and
// the simulators load. Relative paths are resolved against the config
// file's folder.
#include <optional>
#include <string>
#include <vector>

#include "tofguard/common/yaml_reader.hpp"

namespace tofguard {

struct RobotSettings {
  // robot.id: joint_state_t.robot_id of the arm watched.
  std::string id;
  // robot.urdf: the arm's URDF, an existing file.
  std::string urdf_path;
  // robot.package_paths (optional): folders searched for package://NAME/...
  // mesh URIs: NAME is looked up as a sub-folder of each.
  std::vector<std::string> package_paths;
};

struct EnvironmentSettings {
  // environment.urdfs: static-environment URDFs (fixed joints only), placed
  // in the same world frame as the robot's root link.
  std::vector<std::string> urdf_paths;
};

RobotSettings read_robot_settings(YamlMap section);
// The optional `environment` section (absent: no environment).
EnvironmentSettings read_environment_settings(std::optional<YamlMap> section);

}  // namespace tofguard
