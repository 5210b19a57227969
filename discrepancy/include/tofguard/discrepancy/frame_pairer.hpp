#pragma once
// Pairs each camera frame (TOF_DEPTH) with the rendered frame (TOF_RENDERED)
// and labels (TOF_LABELS) the renderer made for it, by seq, with a bounded
// wait on the monotonic clock and a bounded number of frames waiting.
//
// A camera frame whose partners do not arrive within the timeout (or that
// is pushed out by newer frames) is handed back as unpaired, so that it can
// be published as unusable: a dead renderer must stop the arm, not silence
// the chain. Rendered frames and labels without a camera frame, and
// partners arriving after their seq was finished, are dropped and counted.
// Pure logic: the caller passes the monotonic time.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/depth_image_t.hpp"
#include "tofguard/link_labels_t.hpp"

namespace tofguard::discrepancy {

// A camera frame and what was learned when it arrived.
struct CameraFrame {
  depth_image_t image;
  int64_t depth_hash = 0;
  // Camera frames in a row before this one with the same image.
  int32_t repeat_count = 0;
};

// All parts of one seq. `rendered` is absent when the labels say the frame
// is unusable (the renderer need not send a depth image then).
struct PairedFrame {
  CameraFrame camera;
  std::optional<depth_image_t> rendered;
  link_labels_t labels;
};

struct UnpairedFrame {
  CameraFrame camera;
  // One line: what was missing and how long it was waited for.
  std::string reason;
};

struct PairingOutput {
  std::vector<PairedFrame> paired;
  std::vector<UnpairedFrame> unpaired;
  // Rendered frames / labels dropped (no camera frame, late, pushed out).
  int dropped_partners = 0;
};

class FramePairer {
 public:
  FramePairer(int64_t timeout_us, int max_pending);

  void add_camera(CameraFrame frame, int64_t now_us, PairingOutput* out);
  void add_rendered(depth_image_t rendered, int64_t now_us, PairingOutput* out);
  void add_labels(link_labels_t labels, int64_t now_us, PairingOutput* out);
  // Hands back every seq that waited longer than the timeout.
  void expire(int64_t now_us, PairingOutput* out);

  size_t pending() const { return pending_.size(); }

 private:
  struct Pending {
    int64_t first_arrival_us = 0;
    std::optional<CameraFrame> camera;
    std::optional<depth_image_t> rendered;
    std::optional<link_labels_t> labels;
  };

  // Stores a rendered frame or labels (`slot`) unless its seq is finished or
  // already has one (then it is dropped).
  template <class Part>
  void add_partner(std::optional<Part> Pending::*slot, Part part, int64_t now_us, PairingOutput* out);
  // nullptr when `seq` was already finished (a late partner).
  Pending* entry(int64_t seq, int64_t now_us, PairingOutput* out);
  void complete_if_ready(int64_t seq, PairingOutput* out);
  void give_up(std::map<int64_t, Pending>::iterator it, const std::string& why, PairingOutput* out);
  void finish(int64_t seq);

  int64_t timeout_us_;
  size_t max_pending_;
  std::map<int64_t, Pending> pending_;
  // Recently finished seqs, to recognise late partners.
  std::deque<int64_t> finished_;
};

}  // namespace tofguard::discrepancy
