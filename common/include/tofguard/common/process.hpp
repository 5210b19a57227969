#pragma once
// What a tofguard-<name> process is, for --help and its messages. Each
// component says it (e.g. risk::process_info()); the one process runner
// (deployment/process_runner.hpp) parses the command line with it.
#include <string>

namespace tofguard {

struct ProcessInfo {
  // e.g. "tofguard-renderer"
  std::string name;
  // One paragraph: what the process does, its channels in and out.
  std::string summary;
  // Tools that only need LCM (e.g. tofguard-reset) may run without --config:
  // they then get the default wire settings (LCM_DEFAULT_URL, default
  // channel names).
  bool config_required = true;
  // Tools with options of their own (tofguard-reset --who ...) get the
  // arguments besides --config; for every other process an argument besides
  // --config is a usage error (exit code 2).
  bool takes_arguments = false;
};

}  // namespace tofguard
