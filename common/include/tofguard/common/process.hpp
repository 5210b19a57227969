#pragma once
// What every tofguard-<name> main() shares: `--config FILE` and `--help`,
// the config loaded and validated before anything else, and a config error
// turned into one line on stderr and exit code 2.
#include <functional>
#include <string>
#include <vector>

#include "tofguard/common/config.hpp"

namespace tofguard {

struct ProcessInfo {
  // e.g. "tofguard-renderer"
  std::string name;
  // One paragraph: what the process does, its channels in and out.
  std::string summary;
  // Tools that only need LCM (e.g. tofguard-reset) may run without --config:
  // they then get default_wire_config().
  bool config_required = true;
};

// Parses the command line: `--config FILE` (required), `--help`. Loads the
// config and calls `body` with it and the remaining arguments. Returns the
// process's exit code: 0 after --help, 2 for a usage or config error, else
// what `body` returns.
int run_process(int argc, char** argv, const ProcessInfo& info,
                const std::function<int(const Config&, const std::vector<std::string>&)>& body);

}  // namespace tofguard
