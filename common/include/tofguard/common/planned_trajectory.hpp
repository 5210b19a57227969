#pragma once
// The arm controller's plan (planned_trajectory_t on PLANNED_TRAJECTORY) as
// a function of time: where each planned joint should be at a utime,
// linear between the plan's points. tofguard-renderer renders the next
// frame ahead from it; tofguard-risk flags a joint state that leaves it.
//
// A new plan replaces the previous one from its first point on: earlier
// points of the previous plan are kept (they still say where the arm should
// have been a moment ago), later ones dropped. Points more than `keep_us`
// older than the newest plan's first point are forgotten.
//
// Times are utime (microseconds since the Unix epoch, the clock of the joint
// states and camera frames); positions radians (revolute) or metres
// (prismatic).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/planned_trajectory_t.hpp"

namespace tofguard {

class PlannedTrajectory {
 public:
  explicit PlannedTrajectory(int64_t keep_us = 2'000'000) : keep_us_(keep_us) {}

  // Adds a plan that passed check_planned_trajectory. A plan for other
  // joints than the kept points' replaces them all.
  void add(const planned_trajectory_t& plan);

  // Every planned joint's position at `utime`; nullopt outside the span
  // [first point, last point] (no extrapolation: beyond its end there is no
  // plan) or when there is no plan.
  std::optional<std::map<std::string, double>> at(int64_t utime) const;

  bool empty() const { return points_.empty(); }
  int64_t first_utime() const { return points_.empty() ? 0 : points_.front().utime; }
  int64_t last_utime() const { return points_.empty() ? 0 : points_.back().utime; }
  const std::vector<std::string>& joint_names() const { return joint_names_; }

 private:
  struct Point {
    int64_t utime;
    std::vector<double> position;  // in joint_names_ order
  };
  int64_t keep_us_;
  std::vector<std::string> joint_names_;
  std::vector<Point> points_;  // strictly increasing utime
};

}  // namespace tofguard
