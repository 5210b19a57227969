#pragma once
// One-line error reports on stderr that cannot flood the log: per key (e.g.
// a channel) at most one line per second; the lines held back are counted
// and the next line says how many. Counting for heartbeats is the caller's
// job (MessageCounters) and is never rate-limited.
#include <cstdint>
#include <map>
#include <string>

namespace tofguard {

// `text` with its line breaks turned into spaces and trailing spaces removed:
// a library's multi-line error text (urdfdom, assimp) fit for the one-line
// report every error gets.
std::string one_line(std::string text);

class ErrorLog {
 public:
  explicit ErrorLog(std::string process_name) : process_name_(std::move(process_name)) {}
  // Prints "<process>: <line>" unless a line with the same key was printed
  // less than a second ago.
  void report(const std::string& key, const std::string& line);
  // The last line reported (printed or held back), for heartbeat status.
  const std::string& last() const { return last_; }

 private:
  struct KeyState {
    int64_t last_print_us = 0;
    int64_t held_back = 0;
    bool printed = false;
  };
  std::string process_name_;
  std::map<std::string, KeyState> keys_;
  std::string last_;
};

}  // namespace tofguard
