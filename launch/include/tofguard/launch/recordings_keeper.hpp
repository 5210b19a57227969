#pragma once
// The black box's housekeeping in tofguard-launch: watches the recordings'
// disk space and prunes them to the recorder's size and age limits
// (log_rotation.hpp chooses which files), saying what it does through
// `report` (tofguard-launch's output).
#include <cstdint>
#include <functional>
#include <string>

#include "tofguard/settings/launch_settings.hpp"

namespace tofguard::launch {

class RecordingsKeeper {
 public:
  RecordingsKeeper(const RecorderSettings& recorder, std::string recordings,
                   std::function<void(const std::string&)> report);

  // A full disk loses the black box (lcm-logger cannot write; it is not
  // required, so the safety chain goes on): say so once when it happens,
  // once when space is back, checked every second. "Full": less than one
  // recording file's worth (max_file_mb) or 1 MB free, whichever is less.
  void check_space(int64_t now_us);

  // Every 5 s, deletes the oldest recordings beyond the size and age limits.
  void prune(int64_t now_us);

 private:
  const RecorderSettings& recorder_;
  std::string recordings_;
  std::function<void(const std::string&)> report_;
  int64_t next_prune_us_ = 0;
  int64_t next_space_check_us_ = 0;
  bool disk_full_ = false;
};

// Bytes free for an unprivileged writer on the filesystem of `dir`, or -1
// when it cannot be read.
int64_t free_bytes(const std::string& dir);

}  // namespace tofguard::launch
