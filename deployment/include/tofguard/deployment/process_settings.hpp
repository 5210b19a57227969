#pragma once
// What each process takes from the deployment config: its own section and
// the shared pieces it needs, nothing else.
#include "tofguard/deployment/config.hpp"
#include "tofguard/settings/view_settings.hpp"

namespace tofguard::deployment {

renderer::RendererProcessSettings renderer_process_settings(const Config& config);
discrepancy::DiscrepancyProcessSettings discrepancy_process_settings(const Config& config);
risk::RiskProcessSettings risk_process_settings(const Config& config);
estimator::EstimatorProcessSettings estimator_process_settings(const Config& config);
intervene::InterveneProcessSettings intervene_process_settings(const Config& config);
intervene::ResetToolSettings reset_tool_settings(const Config& config);
sim::JointsSimProcessSettings joints_sim_process_settings(const Config& config);
sim::SimCameraProcessSettings sim_camera_process_settings(const Config& config);
sim::SimFaultToolSettings sim_fault_tool_settings(const Config& config);
camera::UvcCameraProcessSettings uvc_camera_process_settings(const Config& config);
// Throws ConfigError naming the file when the config has no `launch`
// section.
launch::LaunchProcessSettings launch_process_settings(const Config& config);
// All but fields.protective_at_rest_m, which the risk rules compute
// (risk::field_size): tofguard-view fills it in.
view::ViewSettings view_settings(const Config& config);

}  // namespace tofguard::deployment
