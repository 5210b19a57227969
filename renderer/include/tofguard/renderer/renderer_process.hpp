#pragma once
// tofguard-renderer's wiring: the settings, LCM and the renderer library
// (the frames' rendering and prediction: RendererService,
// renderer_service.hpp; when to render ahead: PredictionSchedule,
// prediction_schedule.hpp).
#include "tofguard/common/process.hpp"
#include "tofguard/renderer/prediction_schedule.hpp"
#include "tofguard/renderer/renderer_service.hpp"
#include "tofguard/settings/renderer_settings.hpp"

namespace tofguard::renderer {

// What tofguard-renderer is, for --help.
ProcessInfo process_info();

// The process: TOF_DEPTH, JOINT_STATE, CAMERA_POSE, PLANNED_TRAJECTORY in,
// TOF_LABELS and TOF_RENDERED out, until SIGINT/SIGTERM. A model that
// cannot be loaded or rendered is a configuration error (exit code 2).
int run_renderer(const RendererProcessSettings& settings);

}  // namespace tofguard::renderer
