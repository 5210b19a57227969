#pragma once
// The config section `auth` (docs/security.md): the key that signs and
// checks every message that can allow motion, or an explicit, loud
// `insecure: true`. There is no default: a config without the section is
// refused.
#include <cstdint>
#include <optional>
#include <string>

#include "tofguard/auth/auth_key.hpp"
#include "tofguard/common/yaml_reader.hpp"

namespace tofguard::auth {

struct AuthSettings {
  // insecure: true runs without authentication: plain SAFETY_RISK and
  // SAFETY_RESET are taken as they come and nothing is signed. For a bench
  // with nobody near the arm only; every process says so loudly at start.
  bool insecure = false;
  // key_file: the deployment's key (auth_key.hpp), resolved against the
  // config's folder; read and checked when the config is loaded, so that a
  // missing key or one open to others is a config error of every process.
  std::string key_file;
  AuthKey key;
  // max_age_ms: the replay window: a message whose utime differs from the
  // receiver's wall clock by more is refused. Microseconds.
  int64_t max_age_us = 0;
};

// Reads the config root's `auth` section; throws ConfigError when it is
// missing or wrong, or when the key file is.
AuthSettings read_auth_settings(YamlMap& root);

// True when messages are signed and checked (a key was read), false under
// insecure: true. Throws ConfigError for settings with neither (not read
// from a config): no process runs with an unset key by default.
bool authenticated(const AuthSettings& settings);

// The loud lines a process prints at start for these settings ("" when
// there is nothing to say).
std::string auth_warning(const AuthSettings& settings);

}  // namespace tofguard::auth
