#pragma once
// Which of the arm's links no camera sees (docs/safety-chain.md, "Several
// cameras"): a link is seen by a camera when its latest usable frame
// compares at least risk.joint_error.min_link_pixels of the link's pixels
// (link_compared). With several cameras a link pixel hidden by the user or
// by a surface beyond discrepancy.near_arm_m of the arm is taken as one
// without a return (num_robot_hidden_by_user, _by_objects), so it is not
// compared: what is compared shows the link or what lies within
// centimetres of it (a moved link, an object against it), which that
// camera judges. Pure logic over discrepancy_t; tofguard-risk says the
// links seen by no camera in its verdicts.
#include <cstddef>
#include <string>
#include <vector>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::risk {

class ArmCoverage {
 public:
  ArmCoverage(size_t cameras, int min_link_pixels);

  // Camera `camera`'s latest usable frame (an unusable one says nothing
  // about the links and is left out).
  void on_frame(size_t camera, const discrepancy_t& frame);

  // The robot links (in the order they were first rendered) that no camera
  // with `counted[camera]` true sees in its latest frame; empty while a
  // counted camera has had no usable frame. A link counts once some camera
  // has rendered a pixel of it: a link without geometry (a root frame)
  // never does, nor, so far, one that has never been in any camera's view.
  std::vector<std::string> unseen_links(const std::vector<bool>& counted) const;
  // The robot links counted so far.
  size_t robot_links() const { return link_names_.size(); }

 private:
  int min_link_pixels_;
  std::vector<std::string> link_names_;
  // Per camera, the robot links its latest usable frame sees; false before
  // its first one (`framed_`).
  std::vector<std::vector<std::string>> seen_;
  std::vector<bool> framed_;
};

// The arm no camera sees beyond `max_fraction` of the robot links counted
// (risk.unseen_arm_max_fraction): a DANGEROUS finding's verdict fields
// (cause UNCLASSIFIED, suspect "risk.unseen_arm_max_fraction", score the
// fraction unseen, threshold the limit, the detail naming the links) put
// on `verdict` unless it is DANGEROUS already; nothing at or below the
// limit. True when it raised the verdict.
bool limit_unseen_arm(const std::vector<std::string>& unseen, size_t robot_links, double max_fraction,
                      risk_t* verdict);

// " [seen by no camera: link6, gripper (2 of 9 robot links)]", or "" when
// `unseen` is empty.
std::string unseen_links_text(const std::vector<std::string>& unseen, size_t robot_links);

}  // namespace tofguard::risk
