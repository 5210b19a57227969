#pragma once
// A process's resources as /proc shows them, for the fault-injection and
// soak tests: CPU time (utime + stime), resident memory and open file
// descriptors.
#include <sys/types.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace tofguard::test {

struct ProcSample {
  bool alive = false;
  double cpu_s = 0;    // utime + stime, seconds
  int64_t rss_kb = 0;  // VmRSS
  int64_t fds = 0;     // entries of /proc/<pid>/fd
  char state = '?';    // R, S, T (stopped), Z ...
};

inline ProcSample sample_proc(pid_t pid) {
  ProcSample s;
  const std::string dir = "/proc/" + std::to_string(pid);
  std::ifstream stat(dir + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return s;
  // Fields after the command name (in parentheses, may hold spaces).
  const size_t close = line.rfind(')');
  if (close == std::string::npos) return s;
  std::istringstream rest(line.substr(close + 2));
  std::string field;
  rest >> s.state;
  // Fields 4..13 then utime (14) and stime (15), counted from 1.
  for (int i = 4; i <= 13; ++i) rest >> field;
  long long utime_ticks = 0, stime_ticks = 0;
  rest >> utime_ticks >> stime_ticks;
  s.cpu_s = static_cast<double>(utime_ticks + stime_ticks) / static_cast<double>(sysconf(_SC_CLK_TCK));
  std::ifstream status(dir + "/status");
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) s.rss_kb = std::stoll(line.substr(6));
  }
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator(dir + "/fd", ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    ++s.fds;
  }
  s.alive = s.state != 'Z' && s.state != 'X';
  return s;
}

}  // namespace tofguard::test
