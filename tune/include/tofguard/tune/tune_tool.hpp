#pragma once
// tofguard-tune: fits the camera's noise model from a nominal recording and
// reports the false-alarm margin (recording_tuner.hpp); prints the report and
// the config lines, and writes the lines to --out.
#include <string>
#include <vector>

#include "tofguard/common/process.hpp"
#include "tofguard/tune/recording_tuner.hpp"

namespace tofguard::tune {

ProcessInfo tune_info();

// `arguments`: --log FILE [--out FILE]. Exit code 0: tuned; 1: the recording
// is not usable or the fitted model not sound (one line on stderr saying
// why), or --out cannot be written; 2: usage error.
int run_tune(const TuneSettings& settings, const std::vector<std::string>& arguments);

}  // namespace tofguard::tune
