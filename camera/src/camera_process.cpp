#include "tofguard/camera/camera_process.hpp"

namespace tofguard::camera {

ProcessInfo process_info() {
  return {"tofguard-camera",
          "Publishes depth frames on TOF_DEPTH from a USB ToF camera (libuvc) or the simulated ToF camera."};
}

}  // namespace tofguard::camera
