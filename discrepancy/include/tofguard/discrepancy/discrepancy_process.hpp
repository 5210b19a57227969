#pragma once
// tofguard-discrepancy: pairs TOF_DEPTH with TOF_RENDERED + TOF_LABELS by
// seq and publishes one discrepancy_t per camera frame on SAFETY_DISCREPANCY
// (unusable when the pair could not be made or compared), and optionally the
// colour discrepancy image (discrepancy_image_t).
#include <string>
#include <vector>

#include "tofguard/common/process.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/settings/discrepancy_settings.hpp"

namespace tofguard::discrepancy {

// What tofguard-discrepancy is, for --help.
ProcessInfo process_info();

// tofguard-discrepancy's options: the config's discrepancy section's
// (discrepancy_options), and, with other cameras' frames as its
// witnesses, the look-through behind occlusions (hidden_volume_options).
DiscrepancyOptions process_discrepancy_options(const DiscrepancyProcessSettings& settings);

// The process body: runs until SIGINT/SIGTERM; returns the exit code.
int run_discrepancy(const DiscrepancyProcessSettings& settings);

}  // namespace tofguard::discrepancy
