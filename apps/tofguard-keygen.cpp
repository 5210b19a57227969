// tofguard-keygen: makes the deployment's key (docs/security.md).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>
#include <string>

#include "tofguard/auth/auth_key.hpp"
#include "tofguard/common/config_error.hpp"

namespace {

constexpr const char* kUsage =
    "usage: tofguard-keygen [--keep-existing] FILE\n\n"
    "Writes a new random 32-byte HMAC-SHA256 key (64 hex digits) to FILE, readable and\n"
    "writable by the current user only (mode 0600). Name FILE in the config's auth.key_file\n"
    "and give the same file to the robot controller that verifies SAFETY_STATUS_AUTH.\n"
    "An existing FILE is never overwritten: remove it first to change the key.\n"
    "--keep-existing: leave an existing FILE as it is and only check it.\n"
    "Exit code 0 written (or kept and valid), 2 otherwise.\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace tofguard;
  bool keep_existing = false;
  std::string path;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (arg == "--keep-existing") {
      keep_existing = true;
    } else if (path.empty() && !arg.empty() && arg[0] != '-') {
      path = arg;
    } else {
      std::cerr << "tofguard-keygen: unexpected argument '" << arg << "'\n" << kUsage;
      return kConfigErrorExitCode;
    }
  }
  if (path.empty()) {
    std::cerr << "tofguard-keygen: no FILE given\n" << kUsage;
    return kConfigErrorExitCode;
  }
  try {
    auth::ensure_sodium();
    struct stat st {};
    if (keep_existing && ::stat(path.c_str(), &st) == 0) {
      const auth::AuthKey key = auth::read_auth_key_file(path);
      std::cout << "tofguard-keygen: kept " << path << " (key id " << key.id << ")\n";
      return 0;
    }
    // O_EXCL: never overwrite a key; 0600 from the start, so the key is
    // never readable by others, not even for a moment.
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd < 0) {
      std::cerr << "tofguard-keygen: " << path << ": cannot create: " << std::strerror(errno)
                << (errno == EEXIST ? " (remove the old key first to change it)" : "") << "\n";
      return kConfigErrorExitCode;
    }
    std::array<uint8_t, auth::kKeyBytes> key{};
    crypto_auth_hmacsha256_keygen(key.data());
    char hex[2 * auth::kKeyBytes + 1];
    sodium_bin2hex(hex, sizeof hex, key.data(), key.size());
    sodium_memzero(key.data(), key.size());
    std::string text = std::string(hex) + "\n";
    sodium_memzero(hex, sizeof hex);
    const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
    const bool closed = ::fchmod(fd, 0600) == 0 && ::close(fd) == 0;  // 0600 even under a loose umask
    sodium_memzero(text.data(), text.size());
    if (!written || !closed) {
      std::cerr << "tofguard-keygen: " << path << ": cannot write the key: " << std::strerror(errno) << "\n";
      ::unlink(path.c_str());
      return kConfigErrorExitCode;
    }
    std::cout << "tofguard-keygen: wrote " << path << " (key id " << auth::read_auth_key_file(path).id
              << ")\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "tofguard-keygen: " << e.what() << "\n";
    return kConfigErrorExitCode;
  }
}
