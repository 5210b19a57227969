#pragma once
// Human-readable names of risk_t's levels and causes and of
// safety_status_t's stops, for log lines, reasons and the spy.
#include <cstdint>
#include <string>

namespace tofguard {

// "SAFE", "WARNING", "DANGEROUS", else "level <n>".
std::string risk_level_name(int8_t level);
// "none", "joint error", "calibration error", "unknown object", "sensor fault",
// "component fault", "unclassified", else "cause <n>".
std::string risk_cause_name(int8_t cause);
// "none", "software stop", "power cut", else "stop <n>".
std::string stop_name(int8_t stop);

}  // namespace tofguard
