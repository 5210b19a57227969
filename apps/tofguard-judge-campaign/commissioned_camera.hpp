#pragma once
// A campaign arm's camera made as imperfect as a real one and commissioned
// as docs/camera.md says ("Commissioning a camera"), in-process: the
// simulated camera gets the static errors of draw_imperfect_camera(seed)
// (camera.sim.residual: nothing downstream of the camera knows them); the
// arm moves through its nominal motion for `seconds` to learn and
// kCheckRecordingLengths times that to check (the frames rendered
// as tofguard-renderer renders them; each recording centred where the arm
// comes nearest the camera, the learning one within motion time 600-1800 s,
// the checking one within 1800-3000 s, as a user's recordings take the arm
// through its workspace); tofguard-tune's passes learn the
// camera's profile on one such recording and measure, with the profile
// applied, the noise, its correlation and the static error left on a
// second; the arm's config then carries what a user would deploy:
// discrepancy.camera_profile, discrepancy.noise, evidence.pixels_per_sample,
// evidence.static_bias_mm and fixed_pattern_sigma_mm.
#include <cstdint>
#include <string>

#include "judge_campaign.hpp"

namespace tofguard::test {

struct CommissionedCamera {
  bool ok = false;
  // Why commissioning refused (tofguard-tune's one line), when !ok.
  std::string error;
  // The arm with the imperfect camera and the commissioned settings,
  // named "<arm> camera <seed>".
  CampaignArm arm;
  // One line: the camera's truth and what commissioning deployed.
  std::string summary;
};

// The check recording is this many times as long as the learning one
// (docs/camera.md: 40 s and 120 s).
constexpr double kCheckRecordingLengths = 3;

CommissionedCamera commission_imperfect_camera(const CampaignArm& arm, uint64_t seed, double seconds = 12);

}  // namespace tofguard::test
