#pragma once
// Which recorder files to delete so that the black box keeps within its
// limits: files older than max_age, then the oldest until the total fits.
// The file being written (the newest) is never chosen. Pure.
#include <cstdint>
#include <string>
#include <vector>

namespace tofguard::launch {

struct LogFileInfo {
  std::string path;
  uint64_t size_bytes = 0;
  int64_t modified_s = 0;  // seconds since the Unix epoch
};

std::vector<std::string> files_to_delete(std::vector<LogFileInfo> files, uint64_t max_total_bytes,
                                         int64_t max_age_s, int64_t now_s);

// The *.lcmlog* files in `dir` (none if it cannot be read).
std::vector<LogFileInfo> list_log_files(const std::string& dir);

}  // namespace tofguard::launch
