#include "tofguard/renderer/renderer_process.hpp"
#include "tofguard/renderer/llvmpipe_threads.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "tofguard/common/clock.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/resident_heap.hpp"
#include "tofguard/common/wire_checks.hpp"

namespace tofguard::renderer {

ProcessInfo process_info() {
  ProcessInfo info{
      "tofguard-renderer",
      "Renders the arm's model at the reported joint angles from the camera's pose: TOF_DEPTH, JOINT_STATE, "
      "CAMERA_POSE, PLANNED_TRAJECTORY (rendering the next frame ahead) -> TOF_RENDERED, TOF_LABELS.\n"
      "Also: tofguard-renderer render --help (one image to PNG files)."};
  info.per_camera = true;
  return info;
}

namespace {

// The service, or null (the error said) when the model cannot be loaded
// or rendered.
std::unique_ptr<RendererService> make_service(const RendererProcessSettings& settings,
                                              const std::string& name) {
  try {
    return std::make_unique<RendererService>(settings);
  } catch (const std::exception& e) {
    // A model that cannot be rendered is a configuration error: nothing is
    // published, so the risk chain sees this process's heartbeat missing.
    std::cerr << name << ": " << e.what() << "\n";
    return nullptr;
  }
}

// JOINT_STATE, CAMERA_POSE and PLANNED_TRAJECTORY into the service (the
// ignored ones counted and reported), TOF_DEPTH as its pending frame.
void subscribe_inputs(LcmNode& node, const RendererProcessSettings& settings, RendererService* service,
                      PredictionSchedule* schedule) {
  node.subscribe<joint_state_t>(
      node.safety(), settings.channels.joint_state,
      [&node, &settings, service](const joint_state_t& state) {
        if (!service->on_joint_state(state)) {
          node.counters().validation_errors++;
          node.errors().report(settings.channels.joint_state,
                               settings.channels.joint_state + ": ignored a message for robot_id '" +
                                   state.robot_id + "' (expected '" + settings.robot.id +
                                   "') or not newer than the last");
        }
      },
      check_joint_state);
  node.subscribe<camera_pose_t>(
      node.safety(), settings.channels.camera_pose,
      [&node, &settings, service](const camera_pose_t& pose) {
        if (!service->on_camera_pose(pose)) {
          node.counters().validation_errors++;
          node.errors().report(settings.channels.camera_pose,
                               settings.channels.camera_pose +
                                   ": utime: expected a pose newer than camera '" + pose.camera_id +
                                   "''s newest, got " + std::to_string(pose.utime) + "; ignored");
        }
      },
      check_camera_pose);
  node.subscribe<planned_trajectory_t>(
      node.safety(), settings.channels.planned_trajectory,
      [service](const planned_trajectory_t& plan) { service->on_plan(plan); }, check_planned_trajectory);
  node.subscribe<depth_image_t>(
      node.images(), settings.channels.depth,
      [&node, service, schedule](const depth_image_t& frame) {
        schedule->frame_arrived(monotonic_us());
        if (service->on_depth(frame)) node.counters().frames_dropped++;
      },
      check_depth_image);
}

// Before rendering, take in everything that has already arrived, so that
// the newest joint states and only the newest frame are used (bounded, so
// that a flood cannot starve the rendering).
void drain(LcmNode& node) {
  for (int i = 0; i < 1000; ++i) {
    const bool safety = node.safety().handleTimeout(0) > 0;
    const bool images = &node.images() != &node.safety() && node.images().handleTimeout(0) > 0;
    if (!safety && !images) return;
  }
}

// A rendered frame's labels (and depth, when usable) out, and the
// heartbeat's status.
void publish_rendered(LcmNode& node, const RendererProcessSettings& settings, const RendererService& service,
                      const RenderedFrame& rendered) {
  node.images().publish(settings.channels.labels, &rendered.labels);
  if (rendered.depth) node.images().publish(settings.channels.rendered, &*rendered.depth);
  node.counters().frames_out++;
  node.heartbeat().set_last_frame_utime(rendered.labels.utime);
  node.heartbeat().set_status(
      (rendered.labels.usable ? "rendering" : "frame unusable: " + rendered.labels.unusable_reason) + "; " +
      RendererService::prediction_status(service.prediction_stats()));
  if (!rendered.labels.usable)
    node.errors().report("unusable", "frame unusable: " + rendered.labels.unusable_reason);
}

}  // namespace

int run_renderer(const RendererProcessSettings& settings) {
  if (!keep_heap_resident())
    std::fprintf(stderr, "tofguard-renderer: warning: mallopt refused keep_heap_resident's settings\n");
  const std::string name = process_info().name;
  // Before the service opens its EGL display (llvmpipe reads it then).
  std::cerr << name << ": " << choose_llvmpipe_threads(settings.camera.intrinsics) << "\n";
  const std::unique_ptr<RendererService> service = make_service(settings, name);
  if (!service) return kConfigErrorExitCode;
  std::cerr << name << ": rendering with " << service->description() << "\n";
  LcmNode node(settings.lcm, settings.channels, name);
  node.heartbeat().set_status("waiting for frames");
  PredictionSchedule schedule;
  subscribe_inputs(node, settings, service.get(), &schedule);

  // Idle: how long to wait for messages before the render ahead is due.
  const auto idle_wait_ms = [&]() -> int {
    if (!service->has_prediction_to_render()) return 20;
    const int64_t left_us = schedule.start_us(service->frame_period_us()) - monotonic_us();
    return left_us <= 0 ? 0 : static_cast<int>(std::min<int64_t>(20, (left_us + 999) / 1000));
  };
  while (node.spin_once(service->has_pending() ? 0 : idle_wait_ms())) {
    if (!service->has_pending()) {
      // Idle: render the next frame ahead (from the plan, else from the
      // joint states) when it is due (no wait left), unless a frame has
      // come meanwhile. A guess from the joint states that finds them too
      // old waits for the next one (the wait above ends with any message).
      drain(node);
      if (!service->has_pending() && service->has_prediction_to_render() && idle_wait_ms() == 0) {
        const int64_t start_us = monotonic_us();
        if (service->render_prediction()) schedule.rendered(monotonic_us() - start_us);
      }
      continue;
    }
    drain(node);
    const std::optional<RenderedFrame> rendered = service->render_pending();
    if (rendered) publish_rendered(node, settings, *service, *rendered);
  }
  return 0;
}

}  // namespace tofguard::renderer
