#pragma once
// Helpers for the model tests: URDF text written to the test output folder,
// rotations built by hand (fixed-axis rpy).
#include <cmath>
#include <filesystem>
#include <string>

#include <Eigen/Geometry>

#include "tool_support.hpp"

namespace tofguard::test {

// Writes `text` to output_dir()/renderer/<name> and returns the path.
inline std::string write_test_file(const std::string& name, const std::string& text) {
  const std::filesystem::path dir = std::filesystem::path(output_dir()) / "renderer";
  std::filesystem::create_directories((dir / name).parent_path());
  write_file((dir / name).string(), text);
  return (dir / name).string();
}

// R = Rz(yaw) * Ry(pitch) * Rx(roll), written out from the elementary
// rotations so that it does not share code with the loader.
inline Eigen::Matrix3d rpy_rotation(double roll, double pitch, double yaw) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch);
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  Eigen::Matrix3d rx, ry, rz;
  rx << 1, 0, 0, 0, cr, -sr, 0, sr, cr;
  ry << cp, 0, sp, 0, 1, 0, -sp, 0, cp;
  rz << cy, -sy, 0, sy, cy, 0, 0, 0, 1;
  return rz * ry * rx;
}

inline Eigen::Isometry3d pose(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = xyz;
  t.linear() = rpy_rotation(rpy.x(), rpy.y(), rpy.z());
  return t;
}

}  // namespace tofguard::test
