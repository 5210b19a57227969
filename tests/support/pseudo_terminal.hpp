#pragma once
// A pseudo-terminal for tests of serial outputs: device() is the slave's
// path (what the code under test opens), the test reads what was written
// from the master side.
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <string>

namespace tofguard::test {

class PseudoTerminal {
 public:
  PseudoTerminal() {
    master_ = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (master_ < 0 || grantpt(master_) != 0 || unlockpt(master_) != 0) return;
    const char* name = ptsname(master_);
    if (name != nullptr) device_ = name;
  }
  ~PseudoTerminal() {
    if (master_ >= 0) close(master_);
  }
  const std::string& device() const { return device_; }
  // Every byte that is there now (non-blocking).
  std::string available() {
    std::string out;
    char buffer[256];
    for (;;) {
      const ssize_t n = read(master_, buffer, sizeof buffer);
      if (n <= 0) break;
      out.append(buffer, static_cast<size_t>(n));
    }
    return out;
  }
  // Bytes written to the device: waits (poll, on the master) until `count`
  // have come or `deadline_ms` passed, and returns what came. A pty hands
  // bytes over asynchronously, so a read right after a write may miss them.
  std::string read_bytes(size_t count, int deadline_ms) {
    std::string out;
    char buffer[256];
    const auto start = std::chrono::steady_clock::now();
    while (out.size() < count) {
      const auto elapsed =
          std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start);
      const int left = deadline_ms - static_cast<int>(elapsed.count());
      if (left <= 0) break;
      pollfd p{master_, POLLIN, 0};
      if (poll(&p, 1, left) <= 0) break;
      const ssize_t n = read(master_, buffer, std::min(sizeof buffer, count - out.size()));
      if (n <= 0) break;
      out.append(buffer, static_cast<size_t>(n));
    }
    return out;
  }
  // Whatever comes within `window_ms` (for "nothing is sent").
  std::string read_within(int window_ms) { return read_bytes(1 << 20, window_ms); }

 private:
  int master_ = -1;
  std::string device_;
};

}  // namespace tofguard::test
