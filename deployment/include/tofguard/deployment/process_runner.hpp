#pragma once
// The one process runner every tofguard-<name> main() goes through:
// `--config FILE` and `--help`, the deployment config loaded and validated
// before anything else, arguments the process does not take rejected, the
// SIGINT/SIGTERM handlers installed (stop_requested(), lcm_node.hpp), and an
// exception turned into one line on stderr and an exit code:
//   0   after --help
//   2   a usage or config error (ConfigError, from the loader or the body)
//   1   any other exception escaping the body
//   otherwise what the body returns (e.g. tofguard-camera's 3 and 4).
#include <functional>
#include <string>
#include <vector>

#include "tofguard/common/process.hpp"
#include "tofguard/deployment/config.hpp"

namespace tofguard::deployment {

// `body` gets the config (default_wire_config() for a tool run without
// --config, when info.config_required is false) and, when
// info.takes_arguments, the arguments besides --config FILE.
using ProcessBody = std::function<int(const Config& config, const std::vector<std::string>& arguments)>;

int run_process(int argc, char** argv, const ProcessInfo& info, const ProcessBody& body);

}  // namespace tofguard::deployment
