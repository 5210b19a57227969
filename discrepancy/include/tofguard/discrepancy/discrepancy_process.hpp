#pragma once
// tofguard-discrepancy: pairs TOF_DEPTH with TOF_RENDERED + TOF_LABELS by
// seq and publishes one discrepancy_t per camera frame on SAFETY_DISCREPANCY
// (unusable when the pair could not be made or compared), and optionally the
// colour discrepancy image (discrepancy_image_t).
#include <string>
#include <vector>

#include "tofguard/common/process.hpp"
#include "tofguard/settings/discrepancy_settings.hpp"

namespace tofguard::discrepancy {

// What tofguard-discrepancy is, for --help.
ProcessInfo process_info();

// The process body: runs until SIGINT/SIGTERM; returns the exit code.
int run_discrepancy(const DiscrepancyProcessSettings& settings);

}  // namespace tofguard::discrepancy
