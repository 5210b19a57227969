#include "tofguard/common/risk_names.hpp"

#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/speed_limit_t.hpp"

namespace tofguard {

bool is_model_mismatch(int8_t cause) {
  return cause == risk_t::CAUSE_JOINT_ERROR || cause == risk_t::CAUSE_CALIBRATION_ERROR ||
         cause == risk_t::CAUSE_UNKNOWN_OBJECT || cause == risk_t::CAUSE_UNCLASSIFIED;
}

bool is_fault_cause(int8_t cause) {
  return cause == risk_t::CAUSE_SENSOR_FAULT || cause == risk_t::CAUSE_COMPONENT_FAULT;
}

std::string risk_level_name(int8_t level) {
  switch (level) {
    case risk_t::SAFE:
      return "SAFE";
    case risk_t::WARNING:
      return "WARNING";
    case risk_t::DANGEROUS:
      return "DANGEROUS";
    default:
      return "level " + std::to_string(level);
  }
}

std::string risk_cause_name(int8_t cause) {
  switch (cause) {
    case risk_t::CAUSE_NONE:
      return "none";
    case risk_t::CAUSE_JOINT_ERROR:
      return "joint error";
    case risk_t::CAUSE_CALIBRATION_ERROR:
      return "calibration error";
    case risk_t::CAUSE_UNKNOWN_OBJECT:
      return "unknown object";
    case risk_t::CAUSE_SENSOR_FAULT:
      return "sensor fault";
    case risk_t::CAUSE_COMPONENT_FAULT:
      return "component fault";
    case risk_t::CAUSE_UNCLASSIFIED:
      return "unclassified";
    default:
      return "cause " + std::to_string(cause);
  }
}

std::string stop_name(int8_t stop) {
  switch (stop) {
    case safety_status_t::STOP_NONE:
      return "none";
    case safety_status_t::STOP_SOFTWARE:
      return "software stop";
    case safety_status_t::STOP_POWER_CUT:
      return "power cut";
    default:
      return "stop " + std::to_string(stop);
  }
}

std::string speed_limit_setter_name(int8_t set_by) {
  switch (set_by) {
    case speed_limit_t::SET_BY_RANGE:
      return "range";
    case speed_limit_t::SET_BY_UNKNOWN_OBJECT:
      return "unknown object";
    case speed_limit_t::SET_BY_BODY_REGION:
      return "body region";
    case speed_limit_t::SET_BY_NO_JUDGEMENT:
      return "no judgement";
    default:
      return "set_by " + std::to_string(set_by);
  }
}

}  // namespace tofguard
