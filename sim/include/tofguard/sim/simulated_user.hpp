#pragma once
// The simulated wheelchair user (camera.sim.user): the occupant model's
// shapes, moved as a living seated person moves (breathing, a turning head,
// a hand shifting on the lap; SimUserSettings says how), for the simulated
// camera to render. The monitor never sees this: it knows the user through
// its occupant model and envelopes only.
//
// Frames and units: shapes in the world frame (the robot's root link),
// metres; the motions along the seat frame's axes (x forward, z up).
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/common/region_shape.hpp"
#include "tofguard/robot_model/occupant_model.hpp"
#include "tofguard/settings/sim_settings.hpp"

namespace tofguard::sim {

class SimulatedUser {
 public:
  // `model`: the occupant model seated at `world_from_seat` (load_occupant
  // with the same pose).
  SimulatedUser(robot_model::OccupantModel model, const Eigen::Isometry3d& world_from_seat,
                const SimUserSettings& settings);

  // Every shape of the user at `t_s` seconds since the camera started, in
  // the world frame.
  std::vector<RegionShape> shapes_at(double t_s) const;

 private:
  robot_model::OccupantModel model_;
  Eigen::Vector3d forward_;  // the seat's x axis in the world
  Eigen::Vector3d up_;       // the seat's z axis in the world
  // A point on the head's vertical turning axis (the neck's centre).
  Eigen::Vector3d neck_center_ = Eigen::Vector3d::Zero();
  SimUserSettings settings_;
};

}  // namespace tofguard::sim
