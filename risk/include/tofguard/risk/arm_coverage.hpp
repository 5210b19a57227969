#pragma once
// Which of the arm's links no camera sees, and what share of the arm's
// surface they are (docs/safety-chain.md, "Several cameras"): a link is
// seen by a camera when its latest usable frame compares at least
// risk.joint_error.min_link_pixels of the link's pixels (link_compared).
// With several cameras a link pixel hidden by the user or by a surface
// beyond discrepancy.near_arm_m of the arm is taken as one without a
// return (num_robot_hidden_by_user, _by_objects), so it is not compared:
// what is compared shows the link or what lies within centimetres of it
// (a moved link, an object against it), which that camera judges. A link
// counts whole, seen or not: the unseen area is the summed surface area
// of the links no camera sees (each link's area from the robot's meshes as
// the renderer draws them, robot_model::robot_link_areas_m2). Pure logic
// over discrepancy_t; tofguard-risk says the unseen links and their share
// in its verdicts.
#include <cstddef>
#include <string>
#include <vector>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::risk {

// A robot link's surface area, m^2.
struct LinkArea {
  std::string name;
  double area_m2 = 0;
};

// Every robot link of the URDF at `urdf_path` with its area
// (robot_model::robot_link_areas_m2), in the tree's link order: the
// `geometry` the renderer draws (renderer.geometry, "visual" or
// "collision"), meshes found through `package_paths`, without the
// renderer's padding or simplification. Throws robot_model::ModelError.
std::vector<LinkArea> read_robot_link_areas(const std::string& urdf_path,
                                            const std::vector<std::string>& package_paths,
                                            const std::string& geometry);

class ArmCoverage {
 public:
  // `robot_link_areas`: every robot link; those of area 0 (a root frame,
  // a link without geometry) are never counted. Throws
  // std::invalid_argument for a negative or non-finite area.
  ArmCoverage(size_t cameras, int min_link_pixels, const std::vector<LinkArea>& robot_link_areas);

  // Camera `camera`'s latest usable frame (an unusable one says nothing
  // about the links and is left out).
  void on_frame(size_t camera, const discrepancy_t& frame);

  // The robot links with a surface (in `robot_link_areas` order) that no
  // camera with `counted[camera]` true sees in its latest frame, a link
  // never in any camera's view among them; empty while a counted camera
  // has had no usable frame.
  std::vector<std::string> unseen_links(const std::vector<bool>& counted) const;
  // The arm's surface area counted, m^2 (0: no link with a surface).
  double total_area_m2() const { return total_area_m2_; }
  // The share of the arm's surface area that `links` (names of robot
  // links) make up, 0..1; 0 for an arm without a surface.
  double area_fraction(const std::vector<std::string>& links) const;

 private:
  int min_link_pixels_;
  std::vector<LinkArea> links_;  // the robot links with a surface
  double total_area_m2_ = 0;
  // Per camera, the robot links its latest usable frame sees; false before
  // its first one (`framed_`).
  std::vector<std::vector<std::string>> seen_;
  std::vector<bool> framed_;
};

// The arm no camera sees beyond `max_fraction` of the arm's surface area
// (risk.unseen_arm_max_fraction; `unseen_fraction` from
// ArmCoverage::area_fraction): a DANGEROUS finding's verdict fields (cause
// UNCLASSIFIED, suspect "risk.unseen_arm_max_fraction", score the fraction
// unseen, threshold the limit, the detail naming the links) put on
// `verdict` unless it is DANGEROUS already; nothing at or below the limit.
// True when it raised the verdict.
bool limit_unseen_arm(const std::vector<std::string>& unseen, double unseen_fraction, double max_fraction,
                      risk_t* verdict);

// " [seen by no camera: link6, gripper (4 % of the arm's surface)]", or ""
// when `unseen` is empty.
std::string unseen_links_text(const std::vector<std::string>& unseen, double unseen_fraction);

}  // namespace tofguard::risk
