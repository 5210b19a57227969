#include "tofguard/common/robot_settings.hpp"

namespace tofguard {

RobotSettings read_robot_settings(YamlMap robot) {
  RobotSettings r;
  r.id = robot.string("id");
  r.urdf_path = robot.existing_path("urdf");
  if (robot.optional("package_paths")) {
    r.package_paths = robot.existing_paths("package_paths", /*directory=*/true);
  }
  robot.finish();
  return r;
}

EnvironmentSettings read_environment_settings(std::optional<YamlMap> env) {
  EnvironmentSettings e;
  if (env) {
    e.urdf_paths = env->existing_paths("urdfs");
    env->finish();
  }
  return e;
}

}  // namespace tofguard
