#include "tofguard/renderer/prediction_schedule.hpp"

#include <algorithm>

namespace tofguard::renderer {

void PredictionSchedule::rendered(int64_t duration_us) {
  durations_us_.push_back(duration_us);
  while (durations_us_.size() > kKeptRenders) durations_us_.pop_front();
}

int64_t PredictionSchedule::start_us(int64_t period_us) const {
  if (period_us <= 0 || last_frame_us_ <= 0 || durations_us_.empty()) return 0;
  const int64_t longest_us = *std::max_element(durations_us_.begin(), durations_us_.end());
  return last_frame_us_ + period_us - (longest_us + longest_us / 4 + kMarginUs);
}

}  // namespace tofguard::renderer
