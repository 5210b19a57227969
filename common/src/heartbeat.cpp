#include "tofguard/common/heartbeat.hpp"

#include <unistd.h>

#include <algorithm>

#include "tofguard/common/clock.hpp"
#include "tofguard/heartbeat_t.hpp"

namespace tofguard {

HeartbeatPublisher::HeartbeatPublisher(lcm::LCM* lcm, std::string channel, std::string process_name,
                                       double rate_hz)
    : lcm_(lcm),
      channel_(std::move(channel)),
      process_name_(std::move(process_name)),
      period_us_(static_cast<int64_t>(1e6 / rate_hz)),
      next_due_us_(monotonic_us()) {}

void HeartbeatPublisher::publish_if_due() {
  const int64_t now_us = monotonic_us();
  if (now_us < next_due_us_) return;
  publish();
  // Keep the rate without bursts after a stall.
  next_due_us_ = std::max(next_due_us_ + period_us_, now_us + period_us_ / 2);
}

int64_t HeartbeatPublisher::us_until_due() const {
  return std::max<int64_t>(0, next_due_us_ - monotonic_us());
}

void HeartbeatPublisher::publish() {
  heartbeat_t hb;
  hb.utime = wall_utime();
  hb.process = process_name_;
  hb.pid = static_cast<int32_t>(getpid());
  hb.seq = seq_++;
  hb.frames_in = counters_.frames_in;
  hb.frames_out = counters_.frames_out;
  hb.frames_dropped = counters_.frames_dropped;
  hb.decode_errors = counters_.decode_errors;
  hb.validation_errors = counters_.validation_errors;
  hb.last_frame_utime = last_frame_utime_;
  hb.status = status_;
  lcm_->publish(channel_, &hb);
}

}  // namespace tofguard
