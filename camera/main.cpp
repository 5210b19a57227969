// tofguard-camera: publishes depth_image_t on TOF_DEPTH from the source the
// config names (camera.source: uvc or sim); see tofguard/camera/camera_sources.hpp.
#include <iostream>

#include "tofguard/camera/camera_process.hpp"
#include "tofguard/camera/camera_sources.hpp"
#include "tofguard/sim/sim_camera_runner.hpp"

int main(int argc, char** argv) {
  const tofguard::ProcessInfo info = tofguard::camera::process_info();
  return tofguard::run_process(
      argc, argv, info, [&](const tofguard::Config& config, const std::vector<std::string>& rest) {
        if (!rest.empty()) {
          std::cerr << info.name << ": unknown argument '" << rest[0] << "'\n";
          return 2;
        }
        if (config.camera.source == "uvc") return tofguard::camera::run_uvc_camera(config);
        return tofguard::sim::run_sim_camera(config);
      });
}
