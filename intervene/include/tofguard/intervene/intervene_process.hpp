#pragma once
// tofguard-intervene: SAFETY_RISK, JOINT_STATE, SAFETY_RESET -> SAFETY_STATUS
// (positive-logic permission to move) at a fixed rate and at once on every
// change, SAFETY_RESET_REPLY, and the power-cut actuator
// (intervene_logic.hpp holds the rules, without LCM or clocks).
#include "tofguard/common/process.hpp"
#include "tofguard/settings/intervene_settings.hpp"

namespace tofguard::intervene {

// What tofguard-intervene is, for --help.
ProcessInfo process_info();

// The process: runs until SIGINT/SIGTERM, then publishes a last "stopped"
// status and cuts the power; returns the exit code.
int run_intervene(const InterveneProcessSettings& settings);

}  // namespace tofguard::intervene
