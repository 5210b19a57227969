#pragma once
// tofguard-spy: watch the live tofguard channels in a terminal.
//   tofguard-spy [--config FILE]                  refreshing status board
//   tofguard-spy [--config FILE] --lines [--channel REGEX]...
//                                                 one decoded line per message
// Listens on both the safety URL and the image URL; decodes by fingerprint.
#include <string>
#include <vector>

#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/process.hpp"

namespace tofguard::spy {

// Runs with or without --config.
ProcessInfo process_info();

// Exit code 0 stopped, 2 usage error, 3 cannot open LCM.
int run_spy(const LcmSettings& lcm, const std::vector<std::string>& arguments);

}  // namespace tofguard::spy
