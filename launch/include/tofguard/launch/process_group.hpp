#pragma once
// A group of child processes started in order, each in its own process
// group (so a stop reaches its children too), restarted with back-off when
// they exit, and stopped together: SIGTERM to every group, SIGKILL to what
// is left after a grace period. Every state change is reported in one line.
#include <sys/types.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tofguard/launch/restart_policy.hpp"

namespace tofguard::launch {

struct ProcessSpec {
  std::string name;
  std::vector<std::string> argv;  // argv[0]: an absolute path
  bool required = true;
  // stdout and stderr are appended here ("" = inherit the launcher's).
  std::string log_path;
};

enum class ProcessState { kNotStarted, kRunning, kWaitingToRestart, kGaveUp, kStopped };
std::string state_name(ProcessState state);

// A bare program name is looked up in `beside_dir` first, then in PATH; a
// name with a '/' must be an executable file. Returns "" when not found.
std::string resolve_program(const std::string& program, const std::string& beside_dir);

class ProcessGroup {
 public:
  using Report = std::function<void(const std::string& line)>;
  ProcessGroup(std::vector<ProcessSpec> specs, const RestartPolicy& policy, Report report);
  ~ProcessGroup();

  // Starts every process, in order.
  void start_all(int64_t now_us);
  // Reaps exited children and restarts those whose back-off has passed.
  void poll(int64_t now_us);
  // Stops every process (and its children): SIGTERM, then SIGKILL after
  // grace_ms; returns when all are gone.
  void stop_all(int grace_ms);

  // One line per process: name, state, pid, restarts, last exit.
  std::string status_table() const;
  // PIDs of the processes running now.
  std::vector<pid_t> running_pids() const;
  bool any_required_gave_up() const;

 private:
  struct Managed;
  void start(Managed& process, int64_t now_us);
  std::vector<std::unique_ptr<Managed>> processes_;
  Report report_;
};

}  // namespace tofguard::launch
