#include "tofguard/common/planned_trajectory.hpp"

#include <algorithm>

namespace tofguard {

void PlannedTrajectory::add(const planned_trajectory_t& plan) {
  if (plan.num_points <= 0) return;
  if (plan.joint_name != joint_names_) {
    joint_names_ = plan.joint_name;
    points_.clear();
  }
  const int64_t first = plan.point_utime[0];
  // Keep the previous plan only before the new one's first point, ending
  // with its value 1 us before it (so that the times in between keep the
  // previous plan's positions instead of blending into the new one's).
  std::optional<Point> last_kept;
  if (const auto before = at(first - 1); before && first - 1 > points_.front().utime) {
    Point p{first - 1, {}};
    for (const std::string& joint : joint_names_) p.position.push_back(before->at(joint));
    last_kept = p;
  }
  points_.erase(std::lower_bound(points_.begin(), points_.end(), first,
                                 [](const Point& p, int64_t t) { return p.utime < t; }),
                points_.end());
  points_.erase(points_.begin(), std::lower_bound(points_.begin(), points_.end(), first - keep_us_,
                                                  [](const Point& p, int64_t t) { return p.utime < t; }));
  if (last_kept && (points_.empty() || points_.back().utime < last_kept->utime))
    points_.push_back(*last_kept);
  for (int i = 0; i < plan.num_points; ++i) points_.push_back({plan.point_utime[i], plan.position[i]});
}

std::optional<std::map<std::string, double>> PlannedTrajectory::at(int64_t utime) const {
  if (points_.empty() || utime < points_.front().utime || utime > points_.back().utime) return std::nullopt;
  const auto after = std::lower_bound(points_.begin(), points_.end(), utime,
                                      [](const Point& p, int64_t t) { return p.utime < t; });
  std::map<std::string, double> result;
  if (after->utime == utime) {
    for (size_t j = 0; j < joint_names_.size(); ++j) result[joint_names_[j]] = after->position[j];
    return result;
  }
  const Point& a = *(after - 1);
  const Point& b = *after;
  const double s = static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime);
  for (size_t j = 0; j < joint_names_.size(); ++j) {
    result[joint_names_[j]] = a.position[j] + s * (b.position[j] - a.position[j]);
  }
  return result;
}

}  // namespace tofguard
