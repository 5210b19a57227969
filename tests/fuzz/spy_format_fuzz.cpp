// libFuzzer target: tofguard-spy's one-line formatter, which decodes every
// message type by its fingerprint (not its channel) and prints it without
// any wire check: it must cope with every message that decodes. Seeds: the
// same valid messages as wire_messages_fuzz.
#include <cstddef>
#include <cstdint>
#include <string>

#include "tofguard/spy/message_format.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > (1u << 20)) return 0;
  const std::string line = tofguard::spy::format_message("FUZZ", data, static_cast<int>(size));
  const std::string type = tofguard::spy::type_of(data, static_cast<int>(size));
  volatile size_t sink = line.size() + type.size();
  (void)sink;
  return 0;
}
