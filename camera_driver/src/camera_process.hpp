#pragma once
#include "tofguard/process.hpp"

namespace tofguard::camera {

// What tofguard-camera is, for --help.
ProcessInfo process_info();

}  // namespace tofguard::camera
