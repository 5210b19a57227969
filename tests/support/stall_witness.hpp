// A thread of the test process that asks to wake every kPeriodUs on the
// monotonic clock (monotonic_us, the clock of LiveChain's arrival times) and records each wake-up later than
// kLateUs: a witness of the machine itself stalling (a virtual machine's CPUs descheduled by its host, or
// every process starved at once), which the chain's processes, at the same priority, suffer alike. A stop of
// the chain within kWindowUs after such a stall is the deadline rules doing their job on a stalled machine
// (fail safe), not a false stop of the judgement.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "tofguard/common/clock.hpp"

namespace tofguard::test {

class StallWitness {
 public:
  static constexpr int64_t kPeriodUs = 2'000;
  // A third of the chain's shortest input deadline (JOINT_STATE, 100 ms in
  // config/sim.yaml): a machine stalled that long has used most of a
  // deadline before any process could act.
  static constexpr int64_t kLateUs = 35'000;
  // How long before a stop a stall explains it: a stall ends a deadline's
  // slack, and the chain then needs up to a deadline (150 ms) and the
  // status's way to the test to say so; 1 s covers the chain catching up.
  static constexpr int64_t kWindowUs = 1'000'000;

  struct Stall {
    int64_t woke_us;  // monotonic, when the late wake-up came
    int64_t late_us;  // how much later than asked
  };

  StallWitness() : thread_([this] { run(); }) {}
  ~StallWitness() {
    stop_ = true;
    thread_.join();
  }
  StallWitness(const StallWitness&) = delete;
  StallWitness& operator=(const StallWitness&) = delete;

  // The longest stall that ended within kWindowUs before `stop_us` (and
  // not after it); late_us 0 when none.
  Stall longest_before(int64_t stop_us) const {
    std::lock_guard<std::mutex> lock(mutex_);
    Stall longest{0, 0};
    for (const Stall& s : stalls_) {
      if (s.woke_us <= stop_us + kPeriodUs && s.woke_us >= stop_us - kWindowUs && s.late_us > longest.late_us)
        longest = s;
    }
    return longest;
  }
  std::vector<Stall> stalls() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stalls_;
  }

 private:
  void run() {
    int64_t wanted_us = monotonic_us() + kPeriodUs;
    while (!stop_) {
      std::this_thread::sleep_until(
          std::chrono::steady_clock::time_point(std::chrono::microseconds(wanted_us)));
      const int64_t woke_us = monotonic_us();
      if (woke_us - wanted_us > kLateUs) {
        std::lock_guard<std::mutex> lock(mutex_);
        stalls_.push_back({woke_us, woke_us - wanted_us});
      }
      wanted_us = std::max(wanted_us, woke_us) + kPeriodUs;
    }
  }

  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  std::vector<Stall> stalls_;
  std::thread thread_;
};

}  // namespace tofguard::test
