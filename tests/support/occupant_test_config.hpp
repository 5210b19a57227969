#pragma once
// An `occupant:` section for config variants (sim_config_variant's
// `appended`): the default occupant model in the wheelchair, with the
// envelopes and clearances docs/safety-chain.md ("The user") derives.
#include <string>

#include "tool_support.hpp"

namespace tofguard::test {

inline std::string occupant_section() {
  return "occupant:\n"
         "  urdf: " +
         source_dir() +
         "/config/models/wheelchair_occupant.urdf\n"
         "  seated_on: wheelchair\n"
         "  payload_kg: 0.5\n"
         "  contact_force_factor: 1.0\n"
         "  regions:\n"
         "    skull_and_forehead: {envelope_m: 0.05, clearance_m: 0.05}\n"
         "    face: {envelope_m: 0.05, clearance_m: 0.03}\n"
         "    neck: {envelope_m: 0.04, clearance_m: 0.05}\n"
         "    back_and_shoulders: {envelope_m: 0.04}\n"
         "    chest: {envelope_m: 0.03}\n"
         "    abdomen: {envelope_m: 0.04}\n"
         "    pelvis: {envelope_m: 0.03}\n"
         "    upper_arm: {envelope_m: 0.06}\n"
         "    forearm: {envelope_m: 0.08}\n"
         "    hand: {envelope_m: 0.10}\n"
         "    thigh: {envelope_m: 0.03}\n"
         "    lower_leg: {envelope_m: 0.05}\n"
         "  presence: {min_modelled_pixels: 200, max_missing_fraction: 0.5}\n";
}

}  // namespace tofguard::test
