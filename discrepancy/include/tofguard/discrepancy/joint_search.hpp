#pragma once
// The naming search of the evidence stage (docs/safety-chain.md,
// "Evidence"; discrepancy_t.joint_search_*): which joint's offset explains
// the measured depth best, also where the linear fit is out of its range
// (a 10° offset moves a link by more pixels than its slope describes, and a
// base joint's offset moves every link).
//
// For each joint and each trial offset, the rendered robot points on the
// links the joint moves are moved as an offset of the joint would move
// them (turned about its axis as rendered, mimic axes with their
// multipliers; a prismatic joint slides along its axis), projected into the
// image with the rendered frame's pinhole intrinsics and compared with the
// measured depth at the pixel they land on. No re-render: a point that the
// offset would hide behind another link still counts (the same for every
// joint, so it does not favour one).
//
// The camera is a candidate too (discrepancy_t.camera_search_*), on frames
// where some joint's offset lowers the cost by 25 or more: moved along or about one axis
// of its optical frame at a time, it moves the robot points and points of
// the surfaces no joint moves (the scene, fixed links) as the moved camera
// would see them. A camera moved sideways shifts the arm as a base joint's
// offset turns it; only the scene's points, which a joint leaves where
// they are, tell the two apart.
//
// Frames and units: the camera's optical frame (x right, y down, z
// forward), millimetres; offsets in radians (metres for prismatic joints),
// seen minus reported. Pure computation: no LCM, no clocks.
#include <cstdint>
#include <vector>

#include "tofguard/common/worker_pool.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy/evidence.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/link_labels_t.hpp"

namespace tofguard::discrepancy {

// Fills summary's search_points, joint_search_offset and joint_search_gain
// (num_joints entries each; every gain 0 when the labels carry no
// kinematics or no robot point is seen) and camera_search_* (axis -1 and
// gain 0 when no joint's offset helps that much or no camera move does). `kinematics` must be `labels`'
// (read_label_kinematics).
//
// explained_static (optional): set to one entry per pixel, 1 where a point
// moved by the best joint's offset (the largest gain) lands on a pixel no
// joint moves in the rendering (environment, fixed links, nothing) and
// matches the measured depth there: a static pixel that the arm, where the
// search sees it, explains (the camera fit leaves it out). All 0 when no
// joint's offset helps; empty when the search could not run.
//
// workers (optional): each trial offset of each joint is one task
// (WorkerPool); they share nothing but read-only inputs, each writes its
// own cost, and the offsets are chosen from the costs in a fixed order, so
// the result does not depend on the threads. nullptr: all on the caller's
// thread.
//
// beside (optional): the caller's own work, run as one more task of the
// coarse trials (on the caller's thread when `workers` is nullptr). It
// does not run when the search stops early (no kinematics, no point): the
// caller then runs it (SideTask::run_once).
void search_joint_offsets(const depth_image_t& camera, const depth_image_t& rendered,
                          const link_labels_t& labels, const LabelKinematics& kinematics,
                          const DepthNoise& noise, const EvidenceOptions& options, discrepancy_t* summary,
                          std::vector<uint8_t>* explained_static = nullptr, WorkerPool* workers = nullptr,
                          SideTask* beside = nullptr);

}  // namespace tofguard::discrepancy
