#include "tofguard/risk/arm_coverage.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "tofguard/robot_model/scene_model.hpp"

namespace tofguard::risk {
namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

std::string percent(double fraction) {
  return std::to_string(static_cast<int>(std::lround(100 * fraction))) + " %";
}

}  // namespace

std::vector<LinkArea> read_robot_link_areas(const std::string& urdf_path,
                                            const std::vector<std::string>& package_paths,
                                            const std::string& geometry) {
  robot_model::SceneOptions options;
  options.geometry = robot_model::parse_geometry_source(geometry);
  options.package_paths = package_paths;
  const robot_model::SceneModel scene = robot_model::load_scene(urdf_path, {}, options);
  const std::vector<double> area_m2 = robot_model::robot_link_areas_m2(scene);
  std::vector<LinkArea> links;
  for (size_t i = 0; i < area_m2.size(); ++i) links.push_back({scene.links[i].name, area_m2[i]});
  return links;
}

ArmCoverage::ArmCoverage(size_t cameras, int min_link_pixels, const std::vector<LinkArea>& robot_link_areas)
    : min_link_pixels_(min_link_pixels), seen_(cameras), framed_(cameras, false) {
  for (const LinkArea& link : robot_link_areas) {
    if (!std::isfinite(link.area_m2) || link.area_m2 < 0) {
      throw std::invalid_argument("ArmCoverage: robot link '" + link.name + "' has area " +
                                  std::to_string(link.area_m2) + " m^2, expected a finite area >= 0");
    }
    if (link.area_m2 == 0) continue;
    links_.push_back(link);
    total_area_m2_ += link.area_m2;
  }
}

void ArmCoverage::on_frame(size_t camera, const discrepancy_t& frame) {
  if (!frame.usable) return;
  std::vector<std::string> seen;
  const int robot_links =
      std::min({frame.num_robot_links, frame.num_links, static_cast<int>(frame.link_name.size()),
                static_cast<int>(frame.link_compared.size())});
  for (int i = 0; i < robot_links; ++i) {
    if (frame.link_compared[i] >= min_link_pixels_) seen.push_back(frame.link_name[i]);
  }
  seen_[camera] = std::move(seen);
  framed_[camera] = true;
}

std::vector<std::string> ArmCoverage::unseen_links(const std::vector<bool>& counted) const {
  for (size_t c = 0; c < framed_.size(); ++c) {
    if (counted[c] && !framed_[c]) return {};
  }
  std::vector<std::string> unseen;
  for (const LinkArea& link : links_) {
    bool seen = false;
    for (size_t c = 0; c < seen_.size() && !seen; ++c) {
      seen = counted[c] && std::find(seen_[c].begin(), seen_[c].end(), link.name) != seen_[c].end();
    }
    if (!seen) unseen.push_back(link.name);
  }
  return unseen;
}

double ArmCoverage::area_fraction(const std::vector<std::string>& links) const {
  if (total_area_m2_ <= 0) return 0;
  double area_m2 = 0;
  for (const LinkArea& link : links_) {
    if (std::find(links.begin(), links.end(), link.name) != links.end()) area_m2 += link.area_m2;
  }
  return area_m2 / total_area_m2_;
}

bool limit_unseen_arm(const std::vector<std::string>& unseen, double unseen_fraction, double max_fraction,
                      risk_t* verdict) {
  if (unseen.empty() || verdict->level == risk_t::DANGEROUS) return false;
  if (!(unseen_fraction > max_fraction)) return false;
  verdict->level = risk_t::DANGEROUS;
  verdict->cause = risk_t::CAUSE_UNCLASSIFIED;
  verdict->suspect = "risk.unseen_arm_max_fraction";
  verdict->score = unseen_fraction;
  verdict->threshold = max_fraction;
  verdict->detail = "arm not seen (fraction of the arm's surface): " + joined(unseen) + ", " +
                    percent(unseen_fraction) + " of the arm's surface seen by no camera, limit " +
                    percent(max_fraction) + "; " + verdict->detail;
  return true;
}

std::string unseen_links_text(const std::vector<std::string>& unseen, double unseen_fraction) {
  if (unseen.empty()) return "";
  return " [seen by no camera: " + joined(unseen) + " (" + percent(unseen_fraction) +
         " of the arm's surface)]";
}

}  // namespace tofguard::risk
