#pragma once
#include "tofguard/process.hpp"

namespace tofguard::joints_sim {

// What tofguard-joints-sim is, for --help.
ProcessInfo process_info();

}  // namespace tofguard::joints_sim
