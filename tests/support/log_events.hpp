#pragma once
// Writing LCM log files in tests without a network: one encoded message per
// event, as lcm-logger writes them.
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace tofguard::test {

// Appends `message` on `channel` to `log` with the event timestamp
// `timestamp_us` (microseconds, as lcm-logger stamps its receive time).
template <class T>
void write_log_event(lcm::LogFile* log, int64_t timestamp_us, const std::string& channel, const T& message) {
  std::vector<uint8_t> data(static_cast<size_t>(message.getEncodedSize()));
  message.encode(data.data(), 0, static_cast<int>(data.size()));
  lcm::LogEvent event;
  event.eventnum = 0;
  event.timestamp = timestamp_us;
  event.channel = channel;
  event.datalen = static_cast<int32_t>(data.size());
  event.data = data.data();
  log->writeEvent(&event);
}

}  // namespace tofguard::test
