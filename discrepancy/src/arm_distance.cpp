#include "tofguard/discrepancy/arm_distance.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

namespace tofguard::discrepancy {
namespace {

Eigen::Vector3d center_of(const link_labels_t& labels, int k) {
  const std::vector<float>& c = labels.arm_sphere_center_m[k];
  return Eigen::Vector3d(c[0], c[1], c[2]);
}

}  // namespace

ArmDistance::ArmDistance(const link_labels_t& labels) {
  const int n = labels.num_arm_spheres;
  if (n <= 0) return;
  // Group by link (a counting sort: links are 0..num_robot_links-1).
  const int num_links = labels.num_robot_links;
  std::vector<std::vector<int>> by_link(num_links);
  for (int k = 0; k < n; ++k) by_link[labels.arm_sphere_link[k]].push_back(k);
  spheres_.reserve(n);
  for (const std::vector<int>& members : by_link) {
    if (members.empty()) continue;
    LinkGroup group;
    group.first = spheres_.size();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (int k : members) {
      spheres_.push_back({center_of(labels, k), labels.arm_sphere_radius_m[k]});
      lo = lo.cwiseMin(spheres_.back().center_m);
      hi = hi.cwiseMax(spheres_.back().center_m);
    }
    group.last = spheres_.size();
    group.center_m = (lo + hi) / 2;
    for (size_t k = group.first; k < group.last; ++k) {
      group.radius_m =
          std::max(group.radius_m, (spheres_[k].center_m - group.center_m).norm() + spheres_[k].radius_m);
    }
    groups_.push_back(group);
  }
}

double ArmDistance::distance_m(const Eigen::Vector3d& point_m, double up_to_m) const {
  if (spheres_.empty()) return std::numeric_limits<double>::infinity();
  // Links nearest first by their bounding sphere; a link whose bound is no
  // nearer than the best so far cannot hold a nearer sphere.
  constexpr size_t kMaxSortedLinks = 64;
  std::array<std::pair<double, size_t>, kMaxSortedLinks> order;
  const size_t num_groups = groups_.size();
  double best = up_to_m;
  if (num_groups <= kMaxSortedLinks) {
    for (size_t g = 0; g < num_groups; ++g) {
      order[g] = {(point_m - groups_[g].center_m).norm() - groups_[g].radius_m, g};
    }
    std::sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(num_groups));
    for (size_t i = 0; i < num_groups && order[i].first < best; ++i) {
      const LinkGroup& group = groups_[order[i].second];
      for (size_t k = group.first; k < group.last; ++k) {
        best = std::min(best, (point_m - spheres_[k].center_m).norm() - spheres_[k].radius_m);
      }
    }
  } else {
    for (const LinkGroup& group : groups_) {
      if ((point_m - group.center_m).norm() - group.radius_m >= best) continue;
      for (size_t k = group.first; k < group.last; ++k) {
        best = std::min(best, (point_m - spheres_[k].center_m).norm() - spheres_[k].radius_m);
      }
    }
  }
  return std::max(0.0, best);
}

std::vector<double> joint_reach_m(const link_labels_t& labels) {
  if (labels.num_axes <= 0 || labels.num_arm_spheres <= 0) return {};
  std::vector<double> reach(labels.num_joints, 0.0);
  // Per axis: the largest distance from it to a point of a sphere on a
  // link it moves (the link's own axis or one above it).
  std::vector<double> axis_reach(labels.num_axes, 0.0);
  for (int k = 0; k < labels.num_arm_spheres; ++k) {
    const Eigen::Vector3d c = center_of(labels, k);
    const double r = labels.arm_sphere_radius_m[k];
    int m = labels.link_axis[labels.arm_sphere_link[k]];
    for (int hops = 0; m >= 0 && hops <= labels.num_axes; ++hops, m = labels.axis_parent[m]) {
      const Eigen::Vector3d o(labels.axis_origin_m[m][0], labels.axis_origin_m[m][1],
                              labels.axis_origin_m[m][2]);
      const Eigen::Vector3d a(labels.axis_direction[m][0], labels.axis_direction[m][1],
                              labels.axis_direction[m][2]);
      const double off_axis_m = (c - o).cross(a).norm();
      axis_reach[m] = std::max(axis_reach[m], off_axis_m + r);
    }
  }
  for (int m = 0; m < labels.num_axes; ++m) {
    const double per_unit = labels.axis_prismatic[m] ? 1.0 : axis_reach[m];
    reach[labels.axis_joint[m]] += std::abs(labels.axis_multiplier[m]) * per_unit;
  }
  return reach;
}

}  // namespace tofguard::discrepancy
