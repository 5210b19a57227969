#pragma once
#include <cstddef>
#include <cstdint>
#include <deque>

namespace tofguard::renderer {

// When tofguard-renderer renders the next frame's prediction ahead, on its
// monotonic clock: as late as still lets the render finish before the frame
// is due, so that it does not take the cores from the stages judging the
// frame just published (tofguard-discrepancy starts on it at once; on the
// 2-core machine a render ahead started at once made the discrepancy stage
// 1-6 ms slower: docs/benchmarks.md, "The render ahead from a plan").
// Due: the last frame's arrival plus the camera period; the render is given
// the longest of its last kKeptRenders durations x 1.25, plus 2 ms. Before
// there is a period or a duration: at once (0).
class PredictionSchedule {
 public:
  static constexpr size_t kKeptRenders = 8;
  static constexpr int64_t kMarginUs = 2000;
  void frame_arrived(int64_t at_us) { last_frame_us_ = at_us; }
  void rendered(int64_t duration_us);
  // Monotonic us at which to start the render ahead (0: at once); a time
  // before now means at once too.
  int64_t start_us(int64_t period_us) const;

 private:
  int64_t last_frame_us_ = 0;
  std::deque<int64_t> durations_us_;
};

}  // namespace tofguard::renderer
