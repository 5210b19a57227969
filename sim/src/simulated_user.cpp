#include "tofguard/sim/simulated_user.hpp"

#include <cmath>
#include <utility>

namespace tofguard::sim {
namespace {

bool is_head(BodyRegion region) {
  return region == BodyRegion::kSkullAndForehead || region == BodyRegion::kFace ||
         region == BodyRegion::kNeck;
}

bool breathes(BodyRegion region) { return region == BodyRegion::kChest || region == BodyRegion::kAbdomen; }

}  // namespace

SimulatedUser::SimulatedUser(robot_model::OccupantModel model, const Eigen::Isometry3d& world_from_seat,
                             const SimUserSettings& settings)
    : model_(std::move(model)),
      forward_(world_from_seat.linear() * Eigen::Vector3d::UnitX()),
      up_(world_from_seat.linear() * Eigen::Vector3d::UnitZ()),
      settings_(settings) {
  for (const robot_model::OccupantPart& part : model_.parts) {
    if (part.region == BodyRegion::kNeck && !part.shapes.empty()) {
      neck_center_ = part.shapes.front().frame_from_shape.translation();
    }
  }
}

std::vector<RegionShape> SimulatedUser::shapes_at(double t_s) const {
  const SimUserSettings& s = settings_;
  const double breath_m = 0.5e-3 * s.breathing_mm * (1 - std::cos(2 * M_PI * t_s / s.breathing_period_s));
  const double head_rad = s.head_turn_rad * std::sin(2 * M_PI * t_s / s.head_period_s);
  const double hand_m = s.hand_motion_m * std::sin(2 * M_PI * t_s / s.hand_period_s);
  // The head turned about the vertical axis through the neck's centre.
  const Eigen::Isometry3d head_turn = Eigen::Translation3d(neck_center_) * Eigen::AngleAxisd(head_rad, up_) *
                                      Eigen::Translation3d(-neck_center_);
  std::vector<RegionShape> out;
  for (const robot_model::OccupantPart& part : model_.parts) {
    Eigen::Isometry3d move = Eigen::Isometry3d::Identity();
    if (is_head(part.region)) {
      move = head_turn;
    } else if (breathes(part.region)) {
      move = Eigen::Translation3d(breath_m * forward_);
    } else if (part.link_name == "hand_right") {
      move = Eigen::Translation3d(hand_m * forward_);
    }
    for (RegionShape shape : part.shapes) {
      shape.frame_from_shape = move * shape.frame_from_shape;
      out.push_back(shape);
    }
  }
  return out;
}

}  // namespace tofguard::sim
