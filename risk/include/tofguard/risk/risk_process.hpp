#pragma once
// tofguard-risk: one risk_t on SAFETY_RISK per SAFETY_DISCREPANCY frame, and
// timeouts (seq -1) at risk.check_period_ms while an input is stale: the
// camera (TOF_DEPTH on the image URL), JOINT_STATE, CAMERA_POSE (when
// required), the discrepancy stream, and the heartbeats of the required
// processes.
#include "tofguard/common/process.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

// What tofguard-risk is, for --help.
ProcessInfo process_info();

// The process body: runs until SIGINT/SIGTERM; returns the exit code.
int run_risk(const RiskProcessSettings& settings);

}  // namespace tofguard::risk
