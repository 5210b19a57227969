#pragma once
// Human-readable names of risk_t's levels and causes and of
// safety_status_t's stops, for log lines, reasons and the spy; and which
// causes are which kind of finding (what tofguard-risk debounces as a fault,
// what tofguard-estimator estimates).
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
// speed_limit_t.set_by as a word ("range", "unknown object", "body region",
// "no judgement").
std::string speed_limit_setter_name(int8_t set_by);

// True for the causes that count as sensor/component faults (SENSOR_FAULT,
// COMPONENT_FAULT; tofguard-risk debounces them with
// risk.sensor_debounce_frames).
bool is_fault_cause(int8_t cause);

// True for the causes of a model mismatch (JOINT_ERROR, CALIBRATION_ERROR,
// UNKNOWN_OBJECT, UNCLASSIFIED): the findings a motion estimate can name.
bool is_model_mismatch(int8_t cause);

}  // namespace tofguard
