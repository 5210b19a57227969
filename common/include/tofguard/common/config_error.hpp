#pragma once
// A configuration error: one line that names the file, the key and what was
// expected. Processes print it and exit with kConfigErrorExitCode before they
// publish anything.
#include <stdexcept>
#include <string>

namespace tofguard {

constexpr int kConfigErrorExitCode = 2;

class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(const std::string& line) : std::runtime_error(line) {}
};

}  // namespace tofguard
