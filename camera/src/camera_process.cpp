#include "tofguard/camera/camera_process.hpp"

namespace tofguard::camera {

ProcessInfo process_info() {
  ProcessInfo info{
      "tofguard-camera",
      "Publishes depth frames on TOF_DEPTH from a USB ToF camera (libuvc) or the simulated ToF camera."};
  info.per_camera = true;
  return info;
}

}  // namespace tofguard::camera
