#pragma once
#include "tofguard/process.hpp"

namespace tofguard::risk {

// What tofguard-risk is, for --help.
ProcessInfo process_info();

}  // namespace tofguard::risk
