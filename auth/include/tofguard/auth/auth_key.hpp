#pragma once
// The deployment's key file (made by tofguard-keygen): 64 hex digits (the
// 32-byte HMAC-SHA256 key) and a newline, readable by its owner only. The
// key is secret: whoever can read it can allow motion. Header-only (see
// message_tag.hpp).
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>

#include "tofguard/auth/message_tag.hpp"

namespace tofguard::auth {

// Reads and checks a key file; throws std::runtime_error with one line
// naming the file and what is wrong: missing, not a regular file, readable
// or writable by group or others, owned by another user than the one
// reading it, or not 64 hex digits.
inline AuthKey read_auth_key_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw std::runtime_error(path + ": no such key file (make one with tofguard-keygen " + path + ")");
  }
  if (!S_ISREG(st.st_mode)) throw std::runtime_error(path + ": not a regular file");
  if ((st.st_mode & 077) != 0) {
    std::ostringstream mode;
    mode << std::oct << (st.st_mode & 0777);
    throw std::runtime_error(path + ": key file is open to group or others (mode 0" + mode.str() +
                             "); it must be readable by the safety user only: chmod 600 " + path);
  }
  if (st.st_uid != ::geteuid()) {
    throw std::runtime_error(path + ": key file is owned by uid " + std::to_string(st.st_uid) +
                             ", not by the user running tofguard (uid " + std::to_string(::geteuid()) + ")");
  }
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the key file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  AuthKey key;
  size_t decoded = 0;
  const char* end = nullptr;
  ensure_sodium();
  if (text.size() != 2 * kKeyBytes ||
      sodium_hex2bin(key.bytes.data(), key.bytes.size(), text.c_str(), text.size(), nullptr, &decoded,
                     &end) != 0 ||
      decoded != kKeyBytes || end != text.c_str() + text.size()) {
    throw std::runtime_error(path + ": expected 64 hex digits (a 32-byte key from tofguard-keygen), got " +
                             std::to_string(text.size()) + " characters");
  }
  key.id = key_id_of(key.bytes);
  return key;
}

}  // namespace tofguard::auth
