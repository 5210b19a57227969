// tofguard-camera: publishes depth_image_t on TOF_DEPTH from the source the
// config names (camera.source: uvc, camera_sources.hpp, or sim,
// tofguard/sim/sim_camera_runner.hpp).
#include "tofguard/camera/camera_process.hpp"
#include "tofguard/camera/camera_sources.hpp"
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/sim/sim_camera_runner.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, camera::process_info(),
      [](const deployment::Config& config, const std::vector<std::string>&) {
        if (config.camera.source == "uvc") {
          return camera::run_uvc_camera(deployment::uvc_camera_process_settings(config));
        }
        return sim::run_sim_camera(deployment::sim_camera_process_settings(config));
      });
}
