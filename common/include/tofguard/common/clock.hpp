#pragma once
// The two clocks of tofguard. utime (wall clock, microseconds since the Unix
// epoch) only names when a camera frame or joint reading was captured and
// pairs data with each other; deadlines are always measured on the
// receiver's monotonic clock, so that a replayed log with old utimes is
// judged exactly like live data.
#include <cstdint>

namespace tofguard {

// Wall clock, microseconds since the Unix epoch.
int64_t wall_utime();

// Monotonic clock (CLOCK_MONOTONIC), microseconds since an arbitrary start.
int64_t monotonic_us();

}  // namespace tofguard
