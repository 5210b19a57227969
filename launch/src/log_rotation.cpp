#include "tofguard/launch/log_rotation.hpp"

#include <sys/stat.h>
#include <algorithm>

#include <filesystem>

namespace tofguard::launch {

std::vector<std::string> files_to_delete(std::vector<LogFileInfo> files, uint64_t max_total_bytes,
                                         int64_t max_age_s, int64_t now_s) {
  std::sort(files.begin(), files.end(), [](const LogFileInfo& a, const LogFileInfo& b) {
    return a.modified_s != b.modified_s ? a.modified_s < b.modified_s : a.path < b.path;
  });
  std::vector<std::string> doomed;
  if (files.size() <= 1) return doomed;
  uint64_t total = 0;
  for (const auto& f : files) total += f.size_bytes;
  // Oldest first; the newest file is being written and always stays.
  for (size_t i = 0; i + 1 < files.size(); ++i) {
    const bool too_old = now_s - files[i].modified_s > max_age_s;
    const bool too_much = total > max_total_bytes;
    if (!too_old && !too_much) break;
    doomed.push_back(files[i].path);
    total -= files[i].size_bytes;
  }
  return doomed;
}

std::vector<LogFileInfo> list_log_files(const std::string& dir) {
  std::vector<LogFileInfo> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.find(".lcmlog") == std::string::npos || !entry.is_regular_file(ec)) continue;
    LogFileInfo info;
    info.path = entry.path().string();
    info.size_bytes = entry.file_size(ec);
    struct stat st;
    if (stat(info.path.c_str(), &st) != 0) continue;
    info.modified_s = st.st_mtime;
    files.push_back(info);
  }
  return files;
}

}  // namespace tofguard::launch
