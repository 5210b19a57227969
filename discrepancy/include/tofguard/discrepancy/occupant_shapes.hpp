#pragma once
// The wheelchair's occupant as the labels carry it (link_labels_t's
// body_region_envelope_m and occupant_shape_*, checked by
// check_link_labels): which body region, if any, a seen surface point is
// (docs/safety-chain.md, "The user"). A point within a region's envelope of
// one of its shapes is that region of the user; a point outside every
// envelope (a hand lifted into the arm's path, a caregiver) is not, and is
// judged as any unexplained surface.
//
// Frame and units: the camera's optical frame (x right, y down, z
// forward), metres.
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/common/region_shape.hpp"
#include "tofguard/link_labels_t.hpp"

namespace tofguard::discrepancy {

class OccupantShapes {
 public:
  // From checked labels; no shapes when they carry none.
  explicit OccupantShapes(const link_labels_t& labels);

  bool empty() const { return shapes_.empty(); }
  int num_shapes() const { return static_cast<int>(shapes_.size()); }
  // The body_region index of shape k (0 <= k < num_shapes()).
  int region_of_shape(int k) const { return shapes_[k].region; }
  // Region r's envelope, metres.
  double envelope_m(int region) const { return envelope_m_[region]; }

  // The region whose envelope holds `point` (the nearest shape's region
  // where several do); -1 when none.
  int region_holding(const Eigen::Vector3d& point) const;

 private:
  struct Shape {
    RegionShape shape;
    int region = -1;
    // A sphere about the shape's centre that holds the shape and its
    // envelope: a point beyond it is skipped without the exact distance.
    double reach_m = 0;
  };
  std::vector<Shape> shapes_;
  std::vector<double> envelope_m_;
};

}  // namespace tofguard::discrepancy
