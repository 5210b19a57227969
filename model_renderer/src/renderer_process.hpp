#pragma once
#include "tofguard/process.hpp"

namespace tofguard::renderer {

// What tofguard-renderer is, for --help.
ProcessInfo process_info();

}  // namespace tofguard::renderer
