#include "tofguard/sim/speed_limit_follower.hpp"

#include <algorithm>

namespace tofguard::sim {
namespace {

// Joint states kept for looking up the scale of a limit's capture.
constexpr int64_t kKeptUs = 2'000'000;
// A scale this small says too little about the full-speed bound.
constexpr double kMinScaleToLearn = 0.05;

}  // namespace

SpeedLimitFollower::SpeedLimitFollower(double margin, double ramp_per_s)
    : margin_(margin), ramp_per_s_(ramp_per_s) {}

void SpeedLimitFollower::on_joint_state(int64_t utime, double scale) {
  published_.emplace_back(utime, scale);
  while (!published_.empty() && published_.front().first < utime - kKeptUs) published_.pop_front();
}

double SpeedLimitFollower::scale_at(int64_t utime) const {
  double scale = -1;
  for (const auto& [at, s] : published_) {
    if (at > utime) break;
    scale = s;
  }
  return scale;
}

void SpeedLimitFollower::on_limit(const speed_limit_t& limit, int64_t now_us) {
  limit_m_s_ = limit.max_arm_speed_m_s;
  limit_expires_us_ = now_us + int64_t{limit.valid_for_ms} * 1000;
  const double scale = scale_at(limit.utime);
  if (limit.arm_speed_m_s >= 0 && scale >= kMinScaleToLearn) {
    full_speed_bound_m_s_ = limit.arm_speed_m_s / scale;
  }
}

double SpeedLimitFollower::next_scale(int64_t now_us, double dt_s) {
  if (limit_expires_us_ < 0 || now_us > limit_expires_us_ || !(limit_m_s_ > 0)) {
    scale_ = 0;
    return scale_;
  }
  // Without a bound to go by, speed up by the ramp alone.
  double target = 1;
  if (full_speed_bound_m_s_ > 0) target = std::min(1.0, margin_ * limit_m_s_ / full_speed_bound_m_s_);
  scale_ = std::min(target, scale_ + ramp_per_s_ * dt_s);
  return scale_;
}

}  // namespace tofguard::sim
