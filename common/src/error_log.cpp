#include "tofguard/common/error_log.hpp"

#include <iostream>

#include "tofguard/common/clock.hpp"

namespace tofguard {

std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

void ErrorLog::report(const std::string& key, const std::string& line) {
  last_ = line;
  KeyState& state = keys_[key];
  const int64_t now_us = monotonic_us();
  if (state.printed && now_us - state.last_print_us < 1'000'000) {
    state.held_back++;
    return;
  }
  std::cerr << process_name_ << ": " << line;
  if (state.held_back > 0) std::cerr << " (+" << state.held_back << " like it held back)";
  std::cerr << std::endl;
  state.printed = true;
  state.last_print_us = now_us;
  state.held_back = 0;
}

}  // namespace tofguard
