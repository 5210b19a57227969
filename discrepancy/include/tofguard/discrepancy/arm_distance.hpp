#pragma once
// Distances from seen surfaces to the arm, for the 3-D protective and
// warning fields (docs/safety-chain.md, "Protective fields"), from what the
// labels carry: the arm's cover of spheres placed at the frame's joints and
// camera pose (link_labels_t.arm_*), and its moving axes.
//
// Frame and units: the camera's optical frame (x right, y down, z
// forward), metres. Pure computation: no LCM, no clocks.
#include <vector>

#include <Eigen/Core>

#include "tofguard/link_labels_t.hpp"

namespace tofguard::discrepancy {

class ArmDistance {
 public:
  // The cover in `labels` (which passed check_link_labels); empty when
  // they carry none.
  explicit ArmDistance(const link_labels_t& labels);

  bool empty() const { return spheres_.empty(); }

  // Distance (m) from `point_m` to the nearest sphere of the cover (0
  // inside one): never more than the distance to the arm's surface
  // (link_labels_t.arm_*). The search stops at `up_to_m`: a point farther
  // than that from every sphere gets a value >= up_to_m (not necessarily
  // its distance). +infinity for an empty cover.
  double distance_m(const Eigen::Vector3d& point_m, double up_to_m) const;

 private:
  struct Sphere {
    Eigen::Vector3d center_m;
    double radius_m;
  };
  // The spheres of one robot link, and a sphere that holds them all: a
  // point at least (|p - center| - radius) from every sphere of the link.
  struct LinkGroup {
    Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
    double radius_m = 0;
    size_t first = 0;  // spheres_[first, last)
    size_t last = 0;
  };
  std::vector<Sphere> spheres_;  // grouped by link
  std::vector<LinkGroup> groups_;
};

// Per joint (link_labels_t.joint_name order): the arm's reach about it, m:
// for a revolute joint the largest distance from its axis (each axis it
// drives, times |multiplier|, summed over them for mimic joints) to any
// point of a sphere on the links those axes move; 1 for a prismatic joint.
// A point of the arm's surface moves at most sum_j |joint speed_j| *
// reach_j (rad/s or m/s times m or 1): the triangle inequality over the
// joints' contributions, whatever their directions. Empty when the labels
// carry no kinematics (num_axes = 0) or no cover.
std::vector<double> joint_reach_m(const link_labels_t& labels);

}  // namespace tofguard::discrepancy
