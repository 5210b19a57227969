#pragma once
// Decoding any tofguard message by its fingerprint (not its channel name,
// so renamed channels decode too) and formatting it as one line, for
// tofguard-spy's line mode and its status board.
#include <cstdint>
#include <optional>
#include <string>

namespace tofguard::spy {

// One decoded message as one line:
//   <CHANNEL> <type> <fields...>
// e.g. "SAFETY_RISK risk_t seq=42 DANGEROUS joint error suspect=a4 score=31.2
// threshold=20 | joint a4 ...". A message of no known type (or one that
// does not decode) gives "<CHANNEL> ? fingerprint 0x... (N bytes)".
std::string format_message(const std::string& channel, const void* data, int size);

// The LCM type name of a message ("risk_t"), or "" if unknown.
std::string type_of(const void* data, int size);

}  // namespace tofguard::spy
