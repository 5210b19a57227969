#include "tofguard/discrepancy/witness_frames.hpp"

#include <cstdlib>
#include <utility>

#include "tofguard/common/camera_profile.hpp"

namespace tofguard::discrepancy {

WitnessFrames::WitnessFrames(std::vector<settings::WitnessCameraSettings> cameras)
    : cameras_(std::move(cameras)), depth_(cameras_.size()), ready_(cameras_.size()) {}

size_t WitnessFrames::index_of(const std::string& id) const {
  size_t c = 0;
  while (c < cameras_.size() && cameras_[c].id != id) ++c;
  return c;
}

void WitnessFrames::add_depth(size_t camera, const depth_image_t& frame) {
  std::deque<depth_image_t>& kept = depth_[camera];
  kept.push_back(frame);
  while (kept.size() > kKept) kept.pop_front();
}

std::string WitnessFrames::add_labels(size_t camera, const link_labels_t& labels) {
  if (!labels.usable || !labels.optical_pose_given) return "";
  std::deque<depth_image_t>& kept = depth_[camera];
  for (auto it = kept.begin(); it != kept.end(); ++it) {
    if (it->seq != labels.seq || it->utime != labels.utime) continue;
    WitnessView view;
    view.camera_id = cameras_[camera].id;
    view.depth = std::move(*it);
    kept.erase(it);
    if (const auto& profile = cameras_[camera].profile) {
      if (std::string why = profile_mismatch(*profile, view.depth); !why.empty()) return why;
      apply_camera_profile(*profile, &view.depth, &labels);
    }
    view.optical_from_world = world_from_optical(labels).inverse();
    std::deque<WitnessView>& ready = ready_[camera];
    ready.push_back(std::move(view));
    while (ready.size() > kKept) ready.pop_front();
    return "";
  }
  return "";
}

std::vector<WitnessView> WitnessFrames::views_at(int64_t utime) const {
  std::vector<WitnessView> views;
  for (size_t c = 0; c < cameras_.size(); ++c) {
    const WitnessView* nearest = nullptr;
    for (const WitnessView& view : ready_[c]) {
      if (nearest == nullptr ||
          std::llabs(view.depth.utime - utime) < std::llabs(nearest->depth.utime - utime))
        nearest = &view;
    }
    if (nearest == nullptr) continue;
    const int64_t offset_us = nearest->depth.utime - utime;
    if (static_cast<double>(std::llabs(offset_us)) > kWitnessFramePeriods * 1e6 / cameras_[c].rate_hz)
      continue;
    views.push_back(*nearest);
    views.back().offset_us = offset_us;
  }
  return views;
}

}  // namespace tofguard::discrepancy
