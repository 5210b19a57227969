// tofguard-renderer: TOF_DEPTH, JOINT_STATE, CAMERA_POSE, PLANNED_TRAJECTORY -> TOF_LABELS,
// TOF_RENDERED (renderer_process.hpp); also the one-shot
// `tofguard-renderer render ...` command (render_cli.hpp).
#include <iostream>
#include <string>
#include <vector>

#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/renderer/render_cli.hpp"
#include "tofguard/renderer/renderer_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  if (argc >= 2 && std::string(argv[1]) == "render") {
    return renderer::run_render_cli(std::vector<std::string>(argv + 2, argv + argc), std::cout, std::cerr);
  }
  return deployment::run_process(
      argc, argv, renderer::process_info(),
      [](const deployment::Config& config, const std::vector<std::string>&) {
        return renderer::run_renderer(deployment::renderer_process_settings(config));
      });
}
