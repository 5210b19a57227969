#pragma once
#include "tofguard/common/process.hpp"

namespace tofguard::camera {

// What tofguard-camera is, for --help.
ProcessInfo process_info();

}  // namespace tofguard::camera
