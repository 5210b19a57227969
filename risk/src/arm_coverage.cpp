#include "tofguard/risk/arm_coverage.hpp"

#include <algorithm>
#include <cmath>

namespace tofguard::risk {

ArmCoverage::ArmCoverage(size_t cameras, int min_link_pixels)
    : min_link_pixels_(min_link_pixels), seen_(cameras), framed_(cameras, false) {}

void ArmCoverage::on_frame(size_t camera, const discrepancy_t& frame) {
  if (!frame.usable) return;
  std::vector<std::string> seen;
  const int robot_links =
      std::min({frame.num_robot_links, frame.num_links, static_cast<int>(frame.link_name.size()),
                static_cast<int>(frame.link_compared.size())});
  const bool has_invalid = static_cast<int>(frame.link_invalid.size()) >= robot_links;
  for (int i = 0; i < robot_links; ++i) {
    const std::string& name = frame.link_name[i];
    // Part of the arm's surface once a camera has rendered it (a link
    // without geometry, such as a root frame, never is).
    const bool rendered = frame.link_compared[i] + (has_invalid ? frame.link_invalid[i] : 0) > 0;
    if (rendered && std::find(link_names_.begin(), link_names_.end(), name) == link_names_.end()) {
      link_names_.push_back(name);
    }
    if (frame.link_compared[i] >= min_link_pixels_) seen.push_back(name);
  }
  seen_[camera] = std::move(seen);
  framed_[camera] = true;
}

std::vector<std::string> ArmCoverage::unseen_links(const std::vector<bool>& counted) const {
  for (size_t c = 0; c < framed_.size(); ++c) {
    if (counted[c] && !framed_[c]) return {};
  }
  std::vector<std::string> unseen;
  for (const std::string& link : link_names_) {
    bool seen = false;
    for (size_t c = 0; c < seen_.size() && !seen; ++c) {
      seen = counted[c] && std::find(seen_[c].begin(), seen_[c].end(), link) != seen_[c].end();
    }
    if (!seen) unseen.push_back(link);
  }
  return unseen;
}

bool limit_unseen_arm(const std::vector<std::string>& unseen, size_t robot_links, double max_fraction,
                      risk_t* verdict) {
  if (robot_links == 0 || verdict->level == risk_t::DANGEROUS) return false;
  const double fraction = static_cast<double>(unseen.size()) / static_cast<double>(robot_links);
  if (!(fraction > max_fraction)) return false;
  std::string names;
  for (const std::string& link : unseen) names += (names.empty() ? "" : ", ") + link;
  verdict->level = risk_t::DANGEROUS;
  verdict->cause = risk_t::CAUSE_UNCLASSIFIED;
  verdict->suspect = "risk.unseen_arm_max_fraction";
  verdict->score = fraction;
  verdict->threshold = max_fraction;
  verdict->detail =
      "arm not seen (fraction of robot links): " + names + ", " + std::to_string(unseen.size()) + " of " +
      std::to_string(robot_links) + " robot links seen by no camera, limit " +
      std::to_string(static_cast<int>(std::lround(100 * max_fraction))) + " %; " + verdict->detail;
  return true;
}

std::string unseen_links_text(const std::vector<std::string>& unseen, size_t robot_links) {
  if (unseen.empty()) return "";
  std::string names;
  for (const std::string& link : unseen) names += (names.empty() ? "" : ", ") + link;
  return " [seen by no camera: " + names + " (" + std::to_string(unseen.size()) + " of " +
         std::to_string(robot_links) + " robot links)]";
}

}  // namespace tofguard::risk
