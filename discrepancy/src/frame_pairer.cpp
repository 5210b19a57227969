#include "tofguard/discrepancy/frame_pairer.hpp"

#include <algorithm>

namespace tofguard::discrepancy {

FramePairer::FramePairer(int64_t timeout_us, int max_pending)
    : timeout_us_(timeout_us), max_pending_(static_cast<size_t>(std::max(1, max_pending))) {}

FramePairer::Pending* FramePairer::entry(int64_t seq, int64_t now_us, PairingOutput* out) {
  if (std::find(finished_.begin(), finished_.end(), seq) != finished_.end()) return nullptr;
  auto it = pending_.find(seq);
  if (it != pending_.end()) return &it->second;
  // Room for one more: push out the oldest seq first.
  while (pending_.size() >= max_pending_) {
    give_up(pending_.begin(),
            "pushed out by newer frames (more than " + std::to_string(max_pending_) + " waiting)", out);
  }
  Pending& fresh = pending_[seq];
  fresh.first_arrival_us = now_us;
  return &fresh;
}

void FramePairer::add_camera(CameraFrame frame, int64_t now_us, PairingOutput* out) {
  const int64_t seq = frame.image.seq;
  Pending* p = entry(seq, now_us, out);
  if (p == nullptr || p->camera) {
    // A repeated seq (camera restarted, or a duplicate): never judged twice.
    out->unpaired.push_back({std::move(frame), "seq " + std::to_string(seq) + " already seen"});
    return;
  }
  p->camera = std::move(frame);
  complete_if_ready(seq, out);
}

template <class Part>
void FramePairer::add_partner(std::optional<Part> Pending::*slot, Part part, int64_t now_us,
                              PairingOutput* out) {
  const int64_t seq = part.seq;
  Pending* p = entry(seq, now_us, out);
  if (p == nullptr || (p->*slot).has_value()) {
    out->dropped_partners++;
    return;
  }
  p->*slot = std::move(part);
  complete_if_ready(seq, out);
}

void FramePairer::add_rendered(depth_image_t rendered, int64_t now_us, PairingOutput* out) {
  add_partner(&Pending::rendered, std::move(rendered), now_us, out);
}

void FramePairer::add_labels(link_labels_t labels, int64_t now_us, PairingOutput* out) {
  add_partner(&Pending::labels, std::move(labels), now_us, out);
}

void FramePairer::complete_if_ready(int64_t seq, PairingOutput* out) {
  auto it = pending_.find(seq);
  Pending& p = it->second;
  if (!p.camera || !p.labels) return;
  if (p.labels->usable && !p.rendered) return;
  out->paired.push_back(PairedFrame{std::move(*p.camera), std::move(p.rendered), std::move(*p.labels)});
  pending_.erase(it);
  finish(seq);
}

void FramePairer::expire(int64_t now_us, PairingOutput* out) {
  for (auto it = pending_.begin(); it != pending_.end();) {
    auto next = std::next(it);
    if (now_us - it->second.first_arrival_us > timeout_us_) {
      give_up(it, "waited " + std::to_string(timeout_us_ / 1000) + " ms", out);
    }
    it = next;
  }
}

void FramePairer::give_up(std::map<int64_t, Pending>::iterator it, const std::string& why,
                          PairingOutput* out) {
  const int64_t seq = it->first;
  Pending& p = it->second;
  if (p.camera) {
    std::string missing;
    if (!p.rendered) missing = "rendered frame";
    if (!p.labels) missing += missing.empty() ? "labels" : " and labels";
    out->unpaired.push_back(
        {std::move(*p.camera), "no " + missing + " for seq " + std::to_string(seq) + ": " + why});
  } else {
    out->dropped_partners += (p.rendered ? 1 : 0) + (p.labels ? 1 : 0);
  }
  pending_.erase(it);
  finish(seq);
}

void FramePairer::finish(int64_t seq) {
  finished_.push_back(seq);
  while (finished_.size() > 4 * max_pending_) finished_.pop_front();
}

}  // namespace tofguard::discrepancy
