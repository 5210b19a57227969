// tofguard-view: camera, model and discrepancy side by side, live or
// exported from a log (view_process.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/risk/protective_field.hpp"
#include "tofguard/view/view_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, view::process_info(),
      [](const deployment::Config& config, const std::vector<std::string>& arguments) {
        view::ViewSettings settings = deployment::view_settings(config);
        // The protective field S with the arm at rest, as tofguard-risk sizes
        // it for this camera's rate (docs/safety-chain.md, "Protective fields").
        settings.fields.protective_at_rest_m =
            risk::field_size(config.risk, risk::chain_response_time_s(config.risk, config.camera.rate_hz), 0)
                .protective_m;
        return view::run_view(settings, arguments);
      });
}
