// tofguard-renderer: TOF_DEPTH, JOINT_STATE, CAMERA_POSE, PLANNED_TRAJECTORY -> TOF_LABELS,
// TOF_RENDERED (see src/renderer_process.hpp); also the one-shot
// `tofguard-renderer render ...` command (src/render_cli.hpp).
#include <iostream>

#include "tofguard/renderer/render_cli.hpp"
#include "tofguard/renderer/renderer_process.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/wire_checks.hpp"

namespace tofguard::renderer {
namespace {

int run(const Config& config, const std::vector<std::string>& rest) {
  const std::string name = process_info().name;
  if (!rest.empty()) {
    std::cerr << name << ": unknown argument '" << rest[0] << "'\n";
    return kConfigErrorExitCode;
  }
  std::unique_ptr<RendererService> service;
  try {
    service = std::make_unique<RendererService>(config);
  } catch (const std::exception& e) {
    // A model that cannot be rendered is a configuration error: nothing is
    // published, so the risk chain sees this process's heartbeat missing.
    std::cerr << name << ": " << e.what() << "\n";
    return kConfigErrorExitCode;
  }
  std::cerr << name << ": rendering with " << service->description() << "\n";
  LcmNode node(config, name);
  node.heartbeat().set_status("waiting for frames");

  node.subscribe<joint_state_t>(
      node.safety(), config.channels.joint_state,
      [&](const joint_state_t& state) {
        if (!service->on_joint_state(state)) {
          node.counters().validation_errors++;
          node.errors().report(config.channels.joint_state,
                               config.channels.joint_state + ": ignored a message for robot_id '" + state.robot_id +
                                   "' (expected '" + config.robot.id + "') or not newer than the last");
        }
      },
      check_joint_state);
  node.subscribe<camera_pose_t>(
      node.safety(), config.channels.camera_pose,
      [&](const camera_pose_t& pose) {
        if (!service->on_camera_pose(pose)) {
          node.counters().validation_errors++;
          node.errors().report(config.channels.camera_pose, config.channels.camera_pose + ": utime: expected a pose newer than camera '" +
                                                                pose.camera_id + "''s newest, got " +
                                                                std::to_string(pose.utime) + "; ignored");
        }
      },
      check_camera_pose);
  node.subscribe<planned_trajectory_t>(
      node.safety(), config.channels.planned_trajectory, [&](const planned_trajectory_t& plan) { service->on_plan(plan); },
      check_planned_trajectory);
  node.subscribe<depth_image_t>(
      node.images(), config.channels.depth,
      [&](const depth_image_t& frame) {
        if (service->on_depth(frame)) node.counters().frames_dropped++;
      },
      check_depth_image);

  // Before rendering, take in everything that has already arrived, so that
  // the newest joint states and only the newest frame are used (bounded, so
  // that a flood cannot starve the rendering).
  const auto drain = [&] {
    for (int i = 0; i < 1000; ++i) {
      const bool safety = node.safety().handleTimeout(0) > 0;
      const bool images = &node.images() != &node.safety() && node.images().handleTimeout(0) > 0;
      if (!safety && !images) return;
    }
  };
  auto status = [&](const std::string& what) {
    const RendererService::PredictionStats& p = service->prediction_stats();
    node.heartbeat().set_status(what + "; prediction: " + std::to_string(p.hits) + " hits, " +
                                std::to_string(p.misses) + " misses, " + std::to_string(p.without) +
                                " frames without one, " + std::to_string(p.rendered) + " rendered ahead");
  };
  while (node.spin_once(service->has_pending() || service->has_prediction_to_render() ? 0 : 20)) {
    if (!service->has_pending()) {
      // Idle: render the next frame ahead from the plan, unless a frame
      // has come meanwhile.
      drain();
      if (!service->has_pending()) service->render_prediction();
      continue;
    }
    drain();
    const std::optional<RenderedFrame> rendered = service->render_pending();
    if (!rendered) continue;
    node.images().publish(config.channels.labels, &rendered->labels);
    if (rendered->depth) node.images().publish(config.channels.rendered, &*rendered->depth);
    node.counters().frames_out++;
    node.heartbeat().set_last_frame_utime(rendered->labels.utime);
    status(rendered->labels.usable ? "rendering" : "frame unusable: " + rendered->labels.unusable_reason);
    if (!rendered->labels.usable) node.errors().report("unusable", "frame unusable: " + rendered->labels.unusable_reason);
  }
  return 0;
}

}  // namespace
}  // namespace tofguard::renderer

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "render") {
    return tofguard::renderer::run_render_cli(std::vector<std::string>(argv + 2, argv + argc), std::cout, std::cerr);
  }
  return tofguard::run_process(argc, argv, tofguard::renderer::process_info(), tofguard::renderer::run);
}
