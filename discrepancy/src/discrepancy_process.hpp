#pragma once
#include "tofguard/process.hpp"

namespace tofguard::discrepancy {

// What tofguard-discrepancy is, for --help.
ProcessInfo process_info();

}  // namespace tofguard::discrepancy
