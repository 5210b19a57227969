// libFuzzer target: the deployment config loader, load_config(path, env),
// on any file content. Every process loads the whole config at start; a
// bad file must end in ConfigError (one line naming the file, the key and
// what was expected), never in a crash or another exception.
//
// The input is written to config.yaml in a scratch folder that also holds
// `models` (a link to config/models), so that config/sim.yaml and its
// variants (the seeds) resolve their relative URDF paths as they do in the
// source tree, and `auth.key` (the fuzz key, mode 0600) for their
// auth.key_file.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "fuzz_auth_key.hpp"
#include "fuzz_scratch.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/deployment/config.hpp"

namespace {

const tofguard::fuzz::Scratch& scratch() {
  static const tofguard::fuzz::Scratch s;
  static const bool linked = [] {
    std::filesystem::create_directory_symlink(
        std::filesystem::path(TOFGUARD_SOURCE_DIR) / "config" / "models", s.folder() / "models");
    const tofguard::auth::AuthKey key = tofguard::fuzz_auth_key();
    char hex[2 * tofguard::auth::kKeyBytes + 1];
    sodium_bin2hex(hex, sizeof hex, key.bytes.data(), key.bytes.size());
    const std::string key_file = s.write("auth.key", std::string(hex) + "\n");
    std::filesystem::permissions(key_file,
                                 std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
    return true;
  }();
  (void)linked;
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 64 * 1024) return 0;  // sim.yaml is 14 KB
  const std::string path = scratch().write("config.yaml", data, size);
  try {
    const tofguard::deployment::Config config = tofguard::deployment::load_config(path, nullptr);
    volatile size_t sink = config.robot.urdf_path.size();
    (void)sink;
  } catch (const tofguard::ConfigError&) {
    // The expected outcome for a bad file.
  }
  return 0;
}
