#include "tofguard/auth/auth_settings.hpp"

#include <stdexcept>

#include "tofguard/common/config_error.hpp"

namespace tofguard::auth {

AuthSettings read_auth_settings(YamlMap& root) {
  std::optional<YamlMap> section = root.optional_map("auth");
  if (!section) {
    root.fail("auth",
              "a mapping with key_file (a key made by tofguard-keygen) and max_age_ms, or insecure: true "
              "(no authentication, for a bench only)",
              "no auth section");
  }
  AuthSettings s;
  s.insecure = section->optional("insecure") && section->boolean("insecure");
  if (s.insecure) {
    if (section->optional("key_file")) {
      section->fail("key_file", "no key_file beside insecure: true (one or the other)");
    }
    section->optional("max_age_ms");  // allowed and unused
  } else {
    if (!section->optional("key_file")) {
      section->fail("key_file", "a key file made by tofguard-keygen (or insecure: true, for a bench only)");
    }
    s.key_file = section->path("key_file");
    try {
      s.key = read_auth_key_file(s.key_file);
    } catch (const std::runtime_error& e) {
      throw ConfigError(section->file() + ": " + section->key_path("key_file") + ": " + e.what());
    }
    s.max_age_us = section->milliseconds_as_us("max_age_ms", 1, 60000);
  }
  section->finish();
  return s;
}

bool authenticated(const AuthSettings& settings) {
  if (settings.insecure) return false;
  if (settings.key.id.empty()) {
    throw ConfigError("auth: no key read and insecure is not set (settings not read from a config?)");
  }
  return true;
}

std::string auth_warning(const AuthSettings& settings) {
  if (!settings.insecure) return "";
  return "WARNING: auth.insecure is true: nothing is authenticated. Any process that reaches the LCM bus can "
         "allow motion (a SAFE verdict, a reset, a status). Never run this way near a person.";
}

}  // namespace tofguard::auth
