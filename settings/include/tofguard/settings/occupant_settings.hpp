#pragma once
// The wheelchair's occupant (config section `occupant`, docs/safety-chain.md,
// "The user"): the body-region model of the user the arm serves, how far
// the real body may be from it, and the per-region rules. Absent: no
// occupant (the chain as without one).
#include <map>
#include <optional>
#include <string>

#include "tofguard/common/body_region.hpp"
#include "tofguard/common/yaml_reader.hpp"

namespace tofguard::settings {

// One body region's entry under occupant.regions (keyed by the region's
// name, common/body_region.hpp).
struct BodyRegionSettings {
  // envelope_m: how far the real body part may be from its model (breathing,
  // a head turned, a hand resting elsewhere), metres. A seen surface within
  // it is this region of the user; the separation to the arm is measured
  // from the envelope's outside.
  double envelope_m = 0;
  // clearance_m: given for a region the arm must never touch (the head and
  // the neck always): the separation the arm keeps, metres. Absent: contact
  // is allowed at the region's permissible contact speed (ISO/TS 15066
  // Annex A).
  std::optional<double> clearance_m;
};

struct OccupantSettings {
  // urdf: the occupant model (resolved path).
  std::string urdf_path;
  // seated_on: the environment link whose frame the URDF's root link is.
  std::string seated_on;
  // payload_kg: the most the arm carries, m_L of ISO/TS 15066 A.3.4 (the
  // robot's effective mass in a contact is M/2 + m_L, M from the arm's
  // URDF <inertial> masses).
  double payload_kg = 0;
  // contact_force_factor: the contact force allowed, as a multiple of the
  // region's quasi-static limit (ISO/TS 15066 Table A.2), in [1, 2]: 1 when
  // the body part cannot recoil (a user who cannot move away, pressed
  // against the wheelchair), up to 2 for a transient contact.
  double contact_force_factor = 1;
  // regions: every body region (common/body_region.hpp), each given; the
  // head and the neck (body_region_is_no_contact) with a clearance_m.
  std::map<BodyRegion, BodyRegionSettings> regions;
  // presence: is the user where the model seats them? When the camera
  // shows at least min_modelled_pixels of the modelled user (its own
  // pixels, silhouettes left out) and more than max_missing_fraction of
  // them see farther than the region's envelope, the chair is empty or the
  // user has slid or fallen: the model no longer describes the scene, and
  // the arm stops (docs/safety-chain.md, "The user").
  int presence_min_modelled_pixels = 0;
  double presence_max_missing_fraction = 0;
};

// Reads the optional section; nullopt when absent. Throws ConfigError.
std::optional<OccupantSettings> read_occupant_settings(std::optional<YamlMap> section);

}  // namespace tofguard::settings

namespace tofguard {
using settings::BodyRegionSettings;
using settings::OccupantSettings;
}  // namespace tofguard
