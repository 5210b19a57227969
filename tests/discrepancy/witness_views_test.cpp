// discrepancy/witness_views.hpp: the volume behind an occluded pixel,
// looked through another camera's frame. Camera A (the judged one) sits at
// the root frame's origin looking along +z; the arm is a sphere of 5 cm at
// 1.5 m before it; a surface at 0.5 m hides it. The witness B stands 1.5 m
// to the side of the arm looking back at it (its optical z along the root
// frame's -x), and sees ray-cast scenes: the arm alone, an object beside
// the arm that A cannot see, and a plate that hides everything from B.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/discrepancy/witness_views.hpp"

namespace tofguard::discrepancy {
namespace {

const Eigen::Vector3d kArmCentre(0, 0, 1.5);
constexpr double kArmRadius = 0.05;

struct Sphere {
  Eigen::Vector3d centre;
  double radius;
};

// The ray's first hit (parameter along `direction`) on a sphere.
std::optional<double> hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, const Sphere& s) {
  const Eigen::Vector3d o = origin - s.centre;
  const double a = direction.squaredNorm();
  const double b = 2 * o.dot(direction);
  const double c = o.squaredNorm() - s.radius * s.radius;
  const double disc = b * b - 4 * a * c;
  if (disc < 0) return std::nullopt;
  const double t = (-b - std::sqrt(disc)) / (2 * a);
  if (t <= 0) return std::nullopt;
  return t;
}

// B's pose: at (1.5, 0, 1.5) in the root frame; optical x along root +y,
// y along root -z, z along root -x.
Eigen::Isometry3d world_from_witness() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = Eigen::Vector3d(0, 1, 0);
  pose.linear().col(1) = Eigen::Vector3d(0, 0, -1);
  pose.linear().col(2) = Eigen::Vector3d(-1, 0, 0);
  pose.translation() = Eigen::Vector3d(1.5, 0, 1.5);
  return pose;
}

// B's frame of `spheres` before a wall 3 m away; `plate_at_m`: a plate
// across its whole view at that distance (Z, m).
WitnessView witness(const std::vector<Sphere>& spheres, std::optional<double> plate_at_m = std::nullopt) {
  WitnessView w;
  w.camera_id = "b";
  depth_image_t& d = w.depth;
  // Wide enough to see the whole hidden ray (to 45 degrees off its axis).
  d.width = 320;
  d.height = 240;
  d.fx = d.fy = 120;
  d.cx = 159.5;
  d.cy = 119.5;
  d.depth_mm.assign(static_cast<size_t>(d.width * d.height), 0);
  const Eigen::Isometry3d pose = world_from_witness();
  for (int v = 0; v < d.height; ++v) {
    for (int u = 0; u < d.width; ++u) {
      // Optical direction with z = 1, so a hit's parameter is its Z.
      const Eigen::Vector3d along((u - d.cx) / d.fx, (v - d.cy) / d.fy, 1.0);
      double z = plate_at_m.value_or(3.0);
      for (const Sphere& s : spheres) {
        if (auto t = hit(pose.translation(), pose.linear() * along, s)) z = std::min(z, *t);
      }
      d.depth_mm[static_cast<size_t>(v * d.width + u)] = static_cast<int16_t>(std::lround(1000 * z));
    }
  }
  w.optical_from_world = pose.inverse();
  return w;
}

link_labels_t arm_cover() {
  link_labels_t l{};
  l.num_robot_links = 1;
  l.num_links = 1;
  l.num_arm_spheres = 1;
  l.arm_sphere_link = {0};
  l.arm_sphere_center_m = {{0.0f, 0.0f, 1.5f}};
  l.arm_sphere_radius_m = {static_cast<float>(kArmRadius)};
  l.arm_cover_max_radius_m = kArmRadius;
  return l;
}

Tolerance tolerance() {
  Tolerance t;
  t.noise.sigma_at_0m_mm = 2;
  t.noise.sigma_per_m2_mm = 1;
  t.sigmas = 4;
  t.model_mm = 15;
  return t;
}

// The pixel on A's optical axis: a surface at 0.5 m hides the arm.
double hidden_on_axis(const std::vector<WitnessView>& witnesses) {
  const link_labels_t labels = arm_cover();
  const ArmDistance arm(labels);
  const HiddenVolumeOptions options = hidden_volume_options(0.04, 1.6);
  return hidden_distance_m(Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d(0, 0, 1.5 - kArmRadius),
                           Eigen::Isometry3d::Identity(), witnesses, arm, tolerance(), options, 2.0);
}

TEST(HiddenVolume, WithoutWitnessesWhatCannotBeSeenIsOccupied) { EXPECT_EQ(hidden_on_axis({}), 0.0); }

TEST(HiddenVolume, AWitnessThatSeesTheVolumeEmptyClearsIt) {
  EXPECT_EQ(hidden_on_axis({witness({{kArmCentre, kArmRadius}})}), std::numeric_limits<double>::infinity());
}

TEST(HiddenVolume, AnObjectTheWitnessSeesIsJudgedByIt) {
  // A 3 cm ball: B's return at its near side lies within B's tolerance of
  // every point of it, so B has seen all of it (and judges it on its own).
  const Sphere object{Eigen::Vector3d(0, 0, 1.32), 0.03};
  EXPECT_EQ(hidden_on_axis({witness({{kArmCentre, kArmRadius}, object})}),
            std::numeric_limits<double>::infinity());
}

TEST(HiddenVolume, WhatIsBehindAnObjectTheWitnessSeesIsAtItsOwnDistance) {
  // A 6 cm ball 9 cm before the arm's surface on A's axis: B sees its near
  // side, and the inside deeper behind it than B's tolerance (32 mm at
  // 1.5 m) is hidden from both.
  const Sphere object{Eigen::Vector3d(0, 0, 1.30), 0.06};
  const double distance_m = hidden_on_axis({witness({{kArmCentre, kArmRadius}, object})});
  // Those points lie 0.10 to 0.16 m from the cover; the distance is a
  // lower bound of at least 3/4 of the truth.
  EXPECT_GT(distance_m, 0.075);
  EXPECT_LT(distance_m, 0.17);
}

TEST(HiddenVolume, AVolumeHiddenFromEveryCameraBesideTheArmIsOccupied) {
  const double distance_m = hidden_on_axis({witness({{kArmCentre, kArmRadius}}, 0.5)});
  // The nearest point B cannot see beyond the layer (d / 2 = 2 cm).
  EXPECT_GE(distance_m, 0.02);
  EXPECT_LT(distance_m, 0.03);
}

TEST(HiddenVolume, AnOlderWitnessFrameBringsWhatItMissedNearerByTheApproachSpeed) {
  const Sphere object{Eigen::Vector3d(0, 0, 1.30), 0.06};
  WitnessView w = witness({{kArmCentre, kArmRadius}, object});
  const double now_m = hidden_on_axis({w});
  w.offset_us = -30000;
  EXPECT_NEAR(hidden_on_axis({w}), now_m - 1.6 * 0.03, 1e-9);
}

TEST(WitnessSaw, NotOutsideItsImageNorBehindItButThroughAPixelWithoutAReturn) {
  WitnessView w = witness({{kArmCentre, kArmRadius}});
  const Tolerance t = tolerance();
  EXPECT_TRUE(witness_saw(w, Eigen::Vector3d(0, 0, 1.3), t));
  // Behind B (root x beyond 1.5), and far outside its view.
  EXPECT_FALSE(witness_saw(w, Eigen::Vector3d(2.0, 0, 1.5), t));
  EXPECT_FALSE(witness_saw(w, Eigen::Vector3d(0, 5, 1.5), t));
  // Inside the arm: B's return is the arm's near side, before the point.
  EXPECT_FALSE(witness_saw(w, kArmCentre, t));
  // A pixel without a return: nothing along its ray returned light.
  const Eigen::Vector3d p = w.optical_from_world * kArmCentre;
  const long u = std::lround(w.depth.fx * p.x() / p.z() + w.depth.cx);
  const long v = std::lround(w.depth.fy * p.y() / p.z() + w.depth.cy);
  w.depth.depth_mm[static_cast<size_t>(v * w.depth.width + u)] = 0;
  EXPECT_TRUE(witness_saw(w, kArmCentre, t));
}

// Two cameras side by side 0.3 m apart, both looking along +z at a wall
// 2 m away (an environment link, every pixel matched): they agree; the
// witness's pose 10 cm off along its axis, and every shared point
// disagrees by 100 mm, beyond the tolerance (39 mm at 2 m).
TEST(Registration, CamerasAgreeOnTheWallTheyShareUnlessOneMoved) {
  depth_image_t wall;
  wall.width = 64;
  wall.height = 48;
  wall.fx = wall.fy = 60;
  wall.cx = 31.5;
  wall.cy = 23.5;
  wall.depth_mm.assign(64 * 48, 2000);
  link_labels_t labels{};
  labels.label.assign(64 * 48, link_labels_t::ENVIRONMENT_FIRST);
  const std::vector<uint8_t> matched(64 * 48, 0);
  WitnessView w;
  w.camera_id = "b";
  w.depth = wall;
  Eigen::Isometry3d world_from_witness = Eigen::Isometry3d::Identity();
  world_from_witness.translation() = Eigen::Vector3d(0.3, 0, 0);
  w.optical_from_world = world_from_witness.inverse();
  Registration r =
      registration(wall, labels, matched.data(), Eigen::Isometry3d::Identity(), {w}, tolerance());
  EXPECT_GT(r.points, 100);
  EXPECT_EQ(r.mismatch_fraction, 0.0);
  EXPECT_NEAR(r.median_mm, 0.0, 1.0);
  world_from_witness.translation() = Eigen::Vector3d(0.3, 0, -0.1);
  w.optical_from_world = world_from_witness.inverse();
  r = registration(wall, labels, matched.data(), Eigen::Isometry3d::Identity(), {w}, tolerance());
  EXPECT_GT(r.points, 100);
  EXPECT_EQ(r.mismatch_fraction, 1.0);
  EXPECT_NEAR(r.median_mm, -100.0, 1.0);
  // The robot's or the user's pixels, or pixels not matched, take no part.
  labels.label.assign(64 * 48, link_labels_t::ROBOT_FIRST);
  EXPECT_EQ(
      registration(wall, labels, matched.data(), Eigen::Isometry3d::Identity(), {w}, tolerance()).points, 0);
}

}  // namespace
}  // namespace tofguard::discrepancy
