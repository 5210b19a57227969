#pragma once
// Seeing what one camera cannot through another camera's frame
// (docs/safety-chain.md, "Several cameras: the volume behind an
// occlusion").
//
// An occluded pixel (a surface nearer than the arm the model renders
// there) hides the volume between that surface and the arm. With one
// camera that volume is occupied: the pixel is at distance 0 from the arm,
// and a harmless object between the camera and the arm stops it. Another
// camera's frame of about the same time ("a witness") shows what that
// volume held: a point counts as seen by a witness when the witness's ray
// through it returns no nearer than the point (less the witness's
// tolerance). Either the ray passed through the point (free), or its
// return is a surface at the point, which the witness's own discrepancy
// judges (the arm, the user, or an unknown object at its own distance to
// the arm). A pixel without a return counts as a ray that passed: nothing
// along it returned light, and an object that returns none is seen by no
// rule of tofguard (the judged camera's own pixels without a return show
// no object either; each camera's sensor rule limits how many it may
// have). Every other point (outside each witness's image, behind it, or
// behind a nearer surface in every witness) is hidden from every camera,
// and so occupied.
//
// Frames and units: each camera's optical frame (x right, y down, z
// forward) and the model's root frame ("world", the URDF's root link);
// metres, except the depth images' millimetres. Pure computation: no LCM,
// no clocks.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy/arm_distance.hpp"
#include "tofguard/link_labels_t.hpp"

namespace tofguard::discrepancy {

struct Tolerance;

// Another camera's frame at about the judged frame's time.
struct WitnessView {
  std::string camera_id;
  // Its frame, corrected by its own commissioned profile where it has one
  // (depth_mm: Z along its optical axis; <= 0: no return).
  depth_image_t depth;
  // Its optical frame from the model's root frame (the inverse of its
  // labels' world_from_optical).
  Eigen::Isometry3d optical_from_world = Eigen::Isometry3d::Identity();
  // Its capture utime less the judged frame's, microseconds.
  int64_t offset_us = 0;
};

// The optical frame's pose in the root frame from labels that carry it
// (link_labels_t.world_from_optical; optical_pose_given true).
Eigen::Isometry3d world_from_optical(const link_labels_t& labels);

// How the volume behind an occluded pixel is examined; derived from the
// risk's settings by hidden_volume_options().
struct HiddenVolumeOptions {
  // Spacing of the points examined along a hidden ray, m.
  double step_m = 0.01;
  // A layer this thick on the arm's cover is not asked of the witnesses,
  // m: where a witness sees the arm's surface from another side, the
  // surface facing the judged camera is hidden from both (a link hides its
  // own far side), and only an object thinner than the layer fits there.
  double layer_m = 0.02;
  // How fast an object may move since a witness's frame, m/s: a hidden
  // point is taken this much nearer per second of the oldest witness's
  // offset.
  double approach_speed_m_s = 1.6;
};

// From the detection capability d = sqrt(risk.unknown_object_min_area_m2)
// (m) and risk.field.approach_speed_m_s: step d / 4, so that an object of
// size d across a hidden ray has points examined inside it; layer d / 2,
// so that an object of size d against the arm still reaches beyond the
// layer by half its size, where a witness must see it.
HiddenVolumeOptions hidden_volume_options(double detection_capability_m, double approach_speed_m_s);

// Whether witness `w` saw `point_world_m` (root frame, m): its pixel at the
// point's projection has no return, or one no nearer than the point's Z
// less `tolerance` at that depth. False outside its image or at or behind
// its optical plane.
bool witness_saw(const WitnessView& w, const Eigen::Vector3d& point_world_m, const Tolerance& tolerance);

// What an occluded pixel may hide, as a distance to the arm (m): of the
// points from `surface_m` (the occluding surface the judged camera sees)
// to `arm_m` (the arm's rendered surface on the same ray), both in the
// judged camera's optical frame (placed in the root frame by
// `world_from_optical`), those no witness saw and that lie beyond
// options.layer_m of the arm's cover: the smallest distance to the cover
// (`arm`), less approach_speed_m_s times the largest |offset_us| of
// `witnesses`, at least 0. Distances are searched up to `up_to_m`: a
// value of up_to_m or more means none of them is nearer. Between computed
// distances a lower bound may stand in (at least 3/4 of the truth).
// +infinity when the witnesses saw every such point; 0 without witnesses
// (what cannot be seen is occupied).
double hidden_distance_m(const Eigen::Vector3d& surface_m, const Eigen::Vector3d& arm_m,
                         const Eigen::Isometry3d& world_from_optical,
                         const std::vector<WitnessView>& witnesses, const ArmDistance& arm,
                         const Tolerance& tolerance, const HiddenVolumeOptions& options, double up_to_m);

// The cameras' registration to each other (discrepancy_t.registration_*):
// the judged frame's pixels of class MATCH on an environment link
// (`pixel_class`, `labels`), every 4th in u and v, at their depth in
// `camera` (optical frame placed by `world_from_optical`), compared with
// each witness's depth where it sees a surface within 3 tolerances of the
// point (farther off: another surface, hidden or beside an edge).
struct Registration {
  int32_t points = 0;
  double median_mm = 0;          // signed: witness depth - the point's depth
  double mismatch_fraction = 0;  // of the points, |difference| beyond the tolerance
};
Registration registration(const depth_image_t& camera, const link_labels_t& labels,
                          const uint8_t* pixel_class, const Eigen::Isometry3d& world_from_optical,
                          const std::vector<WitnessView>& witnesses, const Tolerance& tolerance);

}  // namespace tofguard::discrepancy
