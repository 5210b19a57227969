// tofguard-view: camera, model and discrepancy side by side, live or
// exported from a log (view_process.hpp).
#include "tofguard/deployment/process_runner.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/view/view_process.hpp"

int main(int argc, char** argv) {
  using namespace tofguard;
  return deployment::run_process(
      argc, argv, view::process_info(),
      [](const deployment::Config& config, const std::vector<std::string>& arguments) {
        return view::run_view(deployment::view_settings(config), arguments);
      });
}
