#pragma once
// The other cameras' latest frames, ready to be looked through
// (witness_views.hpp): each camera's TOF_DEPTH paired by seq with its
// TOF_LABELS (which carry where the camera was), corrected by its profile,
// and handed out for a judged frame when captured within
// kWitnessFramePeriods of that camera's frame periods of it. Pure logic: no
// LCM, no clocks (utimes are the frames' capture times, compared with each
// other only).
#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy/witness_views.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/settings/discrepancy_settings.hpp"

namespace tofguard::discrepancy {

// How old (or new) a witness frame may be against the judged frame, in the
// witness camera's frame periods: its newest frame is ready (paired with
// its rendering) a frame's chain latency after its capture, so when a frame
// is judged the other camera's frame of about the same time may not be
// ready yet and its newest is up to one period plus that latency older
// (measured: with one period, 15 % of a 30 Hz camera's frames found none).
// What may have moved meanwhile is taken off the distances
// (HiddenVolumeOptions::approach_speed_m_s).
constexpr double kWitnessFramePeriods = 2.0;

class WitnessFrames {
 public:
  explicit WitnessFrames(std::vector<settings::WitnessCameraSettings> cameras);

  size_t cameras() const { return cameras_.size(); }
  // The index of camera `id` among them, or cameras() when it is none of
  // them (the judged camera itself).
  size_t index_of(const std::string& id) const;
  // Camera `camera`'s frame (passed its wire checks, of that camera).
  void add_depth(size_t camera, const depth_image_t& frame);
  // Camera `camera`'s labels. "" when taken (or not needed: unusable, or
  // without the camera's pose), else why the pair cannot be looked through
  // (its profile does not fit the frame).
  std::string add_labels(size_t camera, const link_labels_t& labels);

  // For a frame captured at `utime`: of each camera, its paired frame
  // captured nearest to it, when within kWitnessFramePeriods / rate_hz of
  // it (none else).
  std::vector<WitnessView> views_at(int64_t utime) const;

 private:
  // Frames kept per camera: the renderer answers a frame within a few
  // frame periods or never.
  static constexpr size_t kKept = 4;
  std::vector<settings::WitnessCameraSettings> cameras_;
  std::vector<std::deque<depth_image_t>> depth_;
  std::vector<std::deque<WitnessView>> ready_;
};

}  // namespace tofguard::discrepancy
