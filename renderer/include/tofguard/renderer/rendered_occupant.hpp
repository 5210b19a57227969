#pragma once
// The wheelchair's occupant in the rendered frame (docs/safety-chain.md,
// "The user"): the occupant model's shapes are drawn into TOF_RENDERED
// like the rest of the scene (the user hides what is behind them, and the
// camera is expected to see them), labelled link_labels_t::OCCUPANT_FIRST
// + shape index, and sent with the labels in the camera's optical frame
// with each region's envelope, so that tofguard-discrepancy can tell the
// user's seen surfaces from unknown objects.
//
// Shape order: the occupant's parts in model order, each part's shapes in
// order; render objects and wire shapes use the same.
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/link_labels_t.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/robot_model/occupant_model.hpp"
#include "tofguard/settings/occupant_settings.hpp"

namespace tofguard::renderer {

// A region shape (world frame) as a DepthRenderer extra object.
ExtraObject extra_object_of(const RegionShape& shape);

// The occupant's shapes (world frame) as DepthRenderer extra objects: the
// render's labels are then kLabelOccupantFirst + shape index there.
std::vector<ExtraObject> occupant_render_objects(const robot_model::OccupantModel& occupant);

// Writes body_region_envelope_m (from `settings`, per labels->body_region)
// and num_occupant_shapes .. occupant_shape_size_m, the shapes seen from
// `world_from_optical`. TOFGUARD_DEMANDs labels->body_region to name every
// region of the occupant (set_rendered_arm_cover writes them) and
// `settings` to give each an envelope.
void set_rendered_occupant(const robot_model::OccupantModel& occupant, const OccupantSettings& settings,
                           const Eigen::Isometry3d& world_from_optical, link_labels_t* labels);

}  // namespace tofguard::renderer
