#pragma once
#include "tofguard/process.hpp"

namespace tofguard::intervention {

// What tofguard-intervene is, for --help.
ProcessInfo process_info();

}  // namespace tofguard::intervention
