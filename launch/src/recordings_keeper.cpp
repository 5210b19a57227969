#include "tofguard/launch/recordings_keeper.hpp"

#include <sys/statvfs.h>

#include <algorithm>
#include <filesystem>
#include <system_error>
#include <utility>

#include "tofguard/common/clock.hpp"
#include "tofguard/launch/log_rotation.hpp"

namespace tofguard::launch {

RecordingsKeeper::RecordingsKeeper(const RecorderSettings& recorder, std::string recordings,
                                   std::function<void(const std::string&)> report)
    : recorder_(recorder), recordings_(std::move(recordings)), report_(std::move(report)) {}

void RecordingsKeeper::check_space(int64_t now_us) {
  if (now_us < next_space_check_us_) return;
  next_space_check_us_ = now_us + 1'000'000;
  const int64_t free = free_bytes(recordings_);
  const int64_t low = std::min<int64_t>(1'000'000, static_cast<int64_t>(recorder_.max_file_mb * 1e6));
  if (free >= 0 && free < low && !disk_full_) {
    disk_full_ = true;
    report_("recorder: ERROR: disk full at " + recordings_ + " (" + std::to_string(free) +
            " bytes free): black-box recordings are being lost; the safety chain is not affected");
  } else if (free >= low && disk_full_) {
    disk_full_ = false;
    report_("recorder: disk space back at " + recordings_ + " (" + std::to_string(free) +
            " bytes free): recording again");
  }
}

void RecordingsKeeper::prune(int64_t now_us) {
  if (now_us < next_prune_us_) return;
  next_prune_us_ = now_us + 5'000'000;
  const auto doomed =
      files_to_delete(list_log_files(recordings_), static_cast<uint64_t>(recorder_.max_total_mb * 1e6),
                      static_cast<int64_t>(recorder_.max_age_h * 3600), wall_utime() / 1'000'000);
  for (const auto& path : doomed) {
    std::error_code ec;
    std::filesystem::remove(path, ec);
    report_("recorder: deleted " + path + " (size or age limit)");
  }
}

int64_t free_bytes(const std::string& dir) {
  struct statvfs fs {};
  if (statvfs(dir.c_str(), &fs) != 0) return -1;
  return static_cast<int64_t>(fs.f_bavail) * static_cast<int64_t>(fs.f_frsize);
}

}  // namespace tofguard::launch
