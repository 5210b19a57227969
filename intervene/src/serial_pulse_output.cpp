#include "tofguard/intervene/serial_pulse_output.hpp"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "tofguard/common/demand.hpp"

namespace tofguard::intervene {

std::string pulse_line_name(PulseLine line) {
  switch (line) {
    case PulseLine::kDtr:
      return "dtr";
    case PulseLine::kRts:
      return "rts";
    case PulseLine::kTx:
      return "tx";
  }
  return "?";
}

SerialPulseOutput::SerialPulseOutput(SerialPulseSettings settings) : settings_(std::move(settings)) {
  TOFGUARD_DEMAND(
      settings_.frequency_hz > 0 && std::isfinite(settings_.frequency_hz),
      "serial pulse output: frequency_hz " + std::to_string(settings_.frequency_hz) + ", expected > 0");
}

SerialPulseOutput::~SerialPulseOutput() {
  if (fd_ >= 0) drive(false);
  close();
}

int64_t SerialPulseOutput::half_period_us() const {
  return std::max<int64_t>(1, std::llround(0.5e6 / settings_.frequency_hz));
}

std::string SerialPulseOutput::open() {
  if (fd_ >= 0) return "";
  const int fd = ::open(settings_.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    return "serial pulse output " + settings_.device + ": cannot open (" + std::strerror(errno) + ")";
  }
  // Raw bytes, no echo or line discipline: 0x55 goes out as it is.
  termios tty{};
  if (tcgetattr(fd, &tty) == 0) {
    cfmakeraw(&tty);
    tcsetattr(fd, TCSANOW, &tty);
  }
  fd_ = fd;
  return "";
}

void SerialPulseOutput::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

std::string SerialPulseOutput::drive(bool high) {
  if (std::string error = open(); !error.empty()) return error;
  const std::string where =
      "serial pulse output " + settings_.device + " (" + pulse_line_name(settings_.line) + ")";
  if (settings_.line == PulseLine::kTx) {
    if (!high) return "";  // nothing sent is low
    const unsigned char byte = 0x55;
    if (::write(fd_, &byte, 1) != 1) {
      const std::string error = where + ": write failed (" + std::strerror(errno) + ")";
      close();
      return error;
    }
    return "";
  }
  int bits = settings_.line == PulseLine::kDtr ? TIOCM_DTR : TIOCM_RTS;
  if (ioctl(fd_, high ? TIOCMBIS : TIOCMBIC, &bits) != 0) {
    const std::string error = where + ": cannot set the line (" + std::strerror(errno) + ")";
    close();
    return error;
  }
  return "";
}

std::string SerialPulseOutput::set_power(bool enabled, const std::string& /*reason*/) {
  enabled_ = enabled;
  if (enabled) return open();
  high_ = false;
  return drive(false);
}

std::string SerialPulseOutput::half_period_tick() {
  if (!enabled_) return "";
  high_ = !high_;
  if (high_) ++pulses_;
  return drive(high_);
}

}  // namespace tofguard::intervene
