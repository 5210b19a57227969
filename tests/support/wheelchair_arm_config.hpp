#pragma once
// The embedded default's deployment (config/sim.yaml: the wheelchair, its
// seated and moving user, the mast camera with its imperfections and its
// commissioned profile) with the Kinova Gen3 of ../shared/robots on the
// default arm's mount instead of the default arm, and the assistive task
// found for it. For the live tests of the user's rules on a second arm.
//
// Frames: a deployment's world is its robot's root link
// (tofguard/common/robot_settings.hpp). The Kinova's root is its base, so
// the room (wheelchair, table, wall, floor) and the camera are placed in
// the base's frame: the default arm's mount (config/models/friend_arm.urdf,
// the room's frame to the default arm's base_link, no rotation) inverted.
#include <Eigen/Geometry>

#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/robot_model/occupant_model.hpp"
#include "tool_support.hpp"

namespace tofguard::test {

// The default arm's base in the room (friend_arm.urdf's fixed joints from
// its root to base_link), metres; its rotation must be none.
inline Eigen::Vector3d default_arm_mount_m() {
  const robot_model::KinematicTree tree =
      robot_model::load_kinematic_tree(source_dir() + "/config/models/friend_arm.urdf");
  const Eigen::Isometry3d room_from_base = robot_model::fixed_link_pose(tree, "base_link");
  if (!room_from_base.linear().isIdentity(1e-12)) {
    throw std::runtime_error("friend_arm.urdf's mount is rotated: the room's URDF below only shifts");
  }
  return room_from_base.translation();
}

// config/models/wheelchair_environment.urdf with every link hung from a
// link `room` that sits at -mount in the arm's base frame; written to
// output_dir()/<name>-room.urdf.
inline std::string room_under_the_mount(const std::string& name, const Eigen::Vector3d& mount_m) {
  std::string text = read_file(source_dir() + "/config/models/wheelchair_environment.urdf");
  const std::string world_parent = "<parent link=\"world\"/>";
  for (size_t at = text.find(world_parent); at != std::string::npos; at = text.find(world_parent, at)) {
    text.replace(at, world_parent.size(), "<parent link=\"room\"/>");
  }
  const std::string root = "<link name=\"world\"/>";
  const auto at = text.find(root);
  if (at == std::string::npos) throw std::runtime_error("wheelchair_environment.urdf has no link 'world'");
  const Eigen::Vector3d room_m = -mount_m;
  text.insert(at + root.size(),
              "\n  <joint name=\"room_joint\" type=\"fixed\"><parent link=\"world\"/>"
              "<child link=\"room\"/><origin xyz=\"" +
                  std::to_string(room_m.x()) + " " + std::to_string(room_m.y()) + " " +
                  std::to_string(room_m.z()) + "\"/></joint>\n  <link name=\"room\"/>");
  const std::string path = output_dir() + "/" + name + "-room.urdf";
  write_file(path, text);
  return path;
}

// The Kinova Gen3's assistive task beside the user: a cup from 18 cm above
// the table to 38 cm before the face model's centre and back. Found by a
// search over the arm's joints (the end effector's target, then every pose
// on the straight joint path checked) that keeps the arm's cover at least 17 cm from the
// head and the neck, 8 cm from the rest of the user, 3 cm above the table
// and 0.92 m from the camera (its profile covers 0.88-3.38 m) along the
// whole move. The nominal motion (without --task) swings about "table".
inline std::string kinova_gen3_joints_sim_section(const std::string& sim_yaml) {
  return "joints_sim:\n"
         "  rate_hz: 100\n" +
         config_line(sim_yaml, "  status_deadline_ms: ") +
         "  motion:\n"
         "    joint_1: {center: -0.352, amplitude: 0.20, period_s: 9.0}\n"
         "    joint_2: {center: 0.958, amplitude: 0.15, period_s: 7.0, phase_rad: 1.0}\n"
         "    joint_3: {center: -2.634, amplitude: 0.20, period_s: 11.0}\n"
         "    joint_4: {center: -1.686, amplitude: 0.15, period_s: 6.0, phase_rad: 2.0}\n"
         "    joint_5: {center: 2.326, amplitude: 0.30, period_s: 8.0}\n"
         "    joint_6: {center: 0.350, amplitude: 0.20, period_s: 5.0, phase_rad: 0.5}\n"
         "    joint_7: {center: -0.848, amplitude: 0.40, period_s: 4.0}\n"
         "  task:\n"
         "    move_s: 5.0\n"
         "    waypoints:\n"
         "      - {name: table, hold_s: 2.0, joints: {joint_1: -0.352, joint_2: 0.958, joint_3: -2.634, "
         "joint_4: -1.686, joint_5: 2.326, joint_6: 0.350, joint_7: -0.848}}\n"
         "      - {name: mouth, hold_s: 3.0, joints: {joint_1: -0.800, joint_2: 0.243, joint_3: -3.000, "
         "joint_4: -2.400, joint_5: 1.808, joint_6: 1.900, joint_7: -0.847}}\n" +
         config_line(sim_yaml, "  plan: {publish: ") + config_line(sim_yaml, "  follow_speed_limit: ");
}

// Writes output_dir()/<name>.yaml (sim_config_variant's) for the Kinova Gen3
// on the wheelchair; nullopt when ../shared/robots has no Kinova Gen3.
inline std::optional<std::string> kinova_gen3_on_the_wheelchair_config(const std::string& name) {
  const std::string root = shared_dir() + "/robots/kinova_gen3";
  const std::string urdf =
      root + "/kortex_description/arms/gen3/7dof/urdf/GEN3-7DOF-NOVISION_FOR_URDF_ARM_V12.urdf";
  if (shared_dir().empty() || !std::filesystem::exists(urdf)) return std::nullopt;
  const std::string sim_yaml = read_file(source_dir() + "/config/sim.yaml");
  const Eigen::Vector3d mount_m = default_arm_mount_m();

  // The mast camera where it was in the room, in the base's frame.
  const std::string camera_line = config_line(sim_yaml, "    translation_m: [");
  Eigen::Vector3d camera_m;
  if (std::sscanf(camera_line.c_str(), " translation_m: [%lf, %lf, %lf]", &camera_m.x(), &camera_m.y(),
                  &camera_m.z()) != 3) {
    throw std::runtime_error("sim.yaml's camera translation_m is not three numbers: " + camera_line);
  }
  camera_m -= mount_m;
  std::ostringstream camera;
  camera << "    translation_m: [" << camera_m.x() << ", " << camera_m.y() << ", " << camera_m.z() << "]\n";

  // The camera's silhouette allowance was measured per link of the default
  // arm; the Kinova's links get the camera's largest (bias_mm).
  const std::string allowance = config_line(sim_yaml, "    silhouette_allowance: ");
  const auto by_link = allowance.find(", by_link:");
  if (by_link == std::string::npos)
    throw std::runtime_error("sim.yaml's silhouette_allowance has no by_link");

  const std::string appended = "robot:\n  id: kinova-gen3-sim\n  urdf: " + urdf + "\n  package_paths: [" +
                               root + "]\nenvironment:\n  urdfs: [" + room_under_the_mount(name, mount_m) +
                               "]\n" + kinova_gen3_joints_sim_section(sim_yaml);
  return sim_config_variant(
      name, {{camera_line, camera.str()}, {allowance, allowance.substr(0, by_link) + "}\n"}}, appended);
}

}  // namespace tofguard::test
