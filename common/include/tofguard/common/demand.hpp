#pragma once
// TOFGUARD_DEMAND(condition, message): a check of an internal invariant, in
// the spirit of Drake's DRAKE_DEMAND. Always on, in Release and
// RelWithDebInfo builds too (it does not depend on NDEBUG, unlike assert).
//
// Use it for what no input can cause, only a bug in tofguard: sizes that the
// code itself made equal, indices it computed, values a checked factory
// already accepted. Input from outside (YAML, LCM messages, command lines) is
// never DEMANDed: it is checked and refused with its one-line error (a
// ConfigError, a wire-check message), and the process carries on or stops
// cleanly.
//
// When the condition is false it writes one line to stderr,
//   tofguard: internal invariant failed: <file>:<line>: <condition>: <message>
// and calls std::abort(). Dying is the fail-safe outcome: a dead process
// stops publishing its SAFETY_HEARTBEAT and its outputs, tofguard-risk and
// tofguard-intervene see the silence within their deadlines, and because
// SAFETY_STATUS is positive logic (motion_allowed must keep arriving) the
// robot controller stops the arm even if tofguard-intervene itself is the
// process that died; the stop latches until an accepted reset. The line is in
// the process's log (tofguard-launch keeps every process's output). Carrying on with a broken invariant could
// instead publish a plausible but wrong "motion allowed".
//
// `message` is any expression convertible to std::string; it is evaluated
// only when the condition fails, so it may build a string with numbers.
#include <cstdio>
#include <cstdlib>
#include <string>

namespace tofguard::internal {

[[noreturn]] inline void demand_failed(const char* condition, const char* file, int line,
                                       const std::string& message) {
  // One fprintf, then an explicit flush: stderr is unbuffered, but the line
  // must be complete before abort() even when it has been redirected.
  std::fprintf(stderr, "tofguard: internal invariant failed: %s:%d: %s: %s\n", file, line, condition,
               message.c_str());
  std::fflush(stderr);
  std::abort();
}

}  // namespace tofguard::internal

#define TOFGUARD_DEMAND(condition, message)                                           \
  do {                                                                                \
    if (!(condition)) {                                                               \
      ::tofguard::internal::demand_failed(#condition, __FILE__, __LINE__, (message)); \
    }                                                                                 \
  } while (0)
