#include "tofguard/common/lcm_node.hpp"

#include <poll.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <stdexcept>

#include "tofguard/common/clock.hpp"

namespace tofguard {
namespace {

std::atomic<bool> g_stop_requested{false};

void on_stop_signal(int) { g_stop_requested = true; }

std::unique_ptr<lcm::LCM> open_lcm(const std::string& url) {
  auto lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) {
    throw std::runtime_error("cannot open LCM at '" + url +
                             "' (for udpm: is there a multicast route? "
                             "ip route add 224.0.0.0/4 dev lo)");
  }
  return lcm;
}

}  // namespace

void install_stop_signal_handlers() {
  struct sigaction action = {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool stop_requested() { return g_stop_requested; }

LcmNode::LcmNode(const LcmSettings& lcm, const ChannelNames& channels, const std::string& process_name,
                 double heartbeat_rate_hz)
    : process_name_(process_name + channels.camera_suffix),
      safety_(open_lcm(lcm.url)),
      images_(lcm.image_url == lcm.url ? nullptr : open_lcm(lcm.image_url)),
      errors_(process_name_),
      heartbeat_(safety_.get(), channels.heartbeat, process_name_, heartbeat_rate_hz) {
  // LCM 1.3 joins a multicast group lazily (first getFileno()/handle()),
  // and publishing needs no receive socket: each URL is joined in join(),
  // on the first subscription on it.
}

void LcmNode::join(lcm::LCM& lcm) {
  lcm.getFileno();
  if (&lcm == safety_.get()) safety_joined_ = true;
  if (&lcm == images_.get()) images_joined_ = true;
}

LcmNode::~LcmNode() = default;

void LcmNode::add_timer(int64_t period_us, std::function<void()> tick) {
  add_timer(period_us, monotonic_us() + period_us, std::move(tick));
}

void LcmNode::add_timer(int64_t period_us, int64_t first_due_us, std::function<void()> tick) {
  timers_.push_back(Timer{period_us, first_due_us, std::move(tick)});
}

bool LcmNode::spin_once(int max_wait_ms) {
  if (stop_requested()) return false;
  int64_t wait_us = std::min<int64_t>(int64_t{max_wait_ms} * 1000, heartbeat_.us_until_due());
  const int64_t now_us = monotonic_us();
  for (const auto& timer : timers_) wait_us = std::min(wait_us, timer.next_us - now_us);
  wait_us = std::max<int64_t>(0, wait_us);

  // Only the joined URLs: polling an LCM instance's fd would join it. A
  // negative fd is ignored by poll (a node that reads nothing waits for its
  // timers and heartbeat only).
  pollfd fds[2] = {{safety_joined_ ? safety_->getFileno() : -1, POLLIN, 0},
                   {images_joined_ ? images_->getFileno() : -1, POLLIN, 0}};
  // Round up so that a wait never ends just before a timer is due.
  const int ready = poll(fds, 2, static_cast<int>((wait_us + 999) / 1000));
  if (ready > 0) {
    if (safety_joined_ && (fds[0].revents & POLLIN)) safety_->handle();
    if (images_joined_ && (fds[1].revents & POLLIN)) images_->handle();
  }

  const int64_t after_us = monotonic_us();
  for (auto& timer : timers_) {
    if (after_us >= timer.next_us) {
      timer.tick();
      // Never burst to catch up: the next tick is one period from now at
      // the latest.
      timer.next_us = std::max(timer.next_us + timer.period_us, after_us + timer.period_us / 2);
    }
  }
  heartbeat_.publish_if_due();
  return !stop_requested();
}

void LcmNode::run() {
  while (spin_once(100)) {
  }
}

}  // namespace tofguard
