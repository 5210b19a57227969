#include "tofguard/launch/process_group.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <thread>

#include "tofguard/common/clock.hpp"

namespace tofguard::launch {

struct ProcessGroup::Managed {
  ProcessSpec spec;
  RestartTracker restarts;
  ProcessState state = ProcessState::kNotStarted;
  pid_t pid = -1;
  int64_t restart_at_us = 0;
  int starts = 0;
  std::string last_exit = "-";
};

std::string state_name(ProcessState state) {
  switch (state) {
    case ProcessState::kNotStarted:
      return "not started";
    case ProcessState::kRunning:
      return "running";
    case ProcessState::kWaitingToRestart:
      return "restarting";
    case ProcessState::kGaveUp:
      return "FAILED (left stopped)";
    case ProcessState::kStopped:
      return "stopped";
  }
  return "?";
}

namespace {

bool is_executable(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && access(path.c_str(), X_OK) == 0;
}

std::string describe_exit(int status) {
  if (WIFEXITED(status)) return "exited with code " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    return "killed by signal " + std::to_string(sig) + " (" + strsignal(sig) + ")";
  }
  return "ended (status " + std::to_string(status) + ")";
}

}  // namespace

std::string resolve_program(const std::string& program, const std::string& beside_dir) {
  if (program.find('/') != std::string::npos) return is_executable(program) ? program : "";
  if (!beside_dir.empty() && is_executable(beside_dir + "/" + program)) return beside_dir + "/" + program;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (!dir.empty() && is_executable(dir + "/" + program)) return dir + "/" + program;
  }
  return "";
}

ProcessGroup::ProcessGroup(std::vector<ProcessSpec> specs, const RestartPolicy& policy, Report report)
    : report_(std::move(report)) {
  for (auto& spec : specs) {
    processes_.push_back(std::make_unique<Managed>(Managed{std::move(spec), RestartTracker(policy)}));
  }
}

ProcessGroup::~ProcessGroup() { stop_all(2000); }

void ProcessGroup::start(Managed& p, int64_t) {
  std::vector<char*> argv;
  for (auto& a : p.spec.argv) argv.push_back(a.data());
  argv.push_back(nullptr);
  // Block SIGINT/SIGTERM across fork: a stop that arrives before the child
  // has reset the launcher's handlers must still end it (it stays pending
  // until the child unblocks it with the default action in place).
  sigset_t stop_signals, old_mask;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  sigprocmask(SIG_BLOCK, &stop_signals, &old_mask);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid != 0) sigprocmask(SIG_SETMASK, &old_mask, nullptr);
  if (pid < 0) {
    report_(p.spec.name + ": cannot fork: " + strerror(errno));
    p.state = ProcessState::kWaitingToRestart;
    return;
  }
  if (pid == 0) {
    setpgid(0, 0);  // its own group: a stop reaches its children too
    // If tofguard-launch itself dies (even by SIGKILL), its processes stop
    // too, so that a restarted launcher (systemd) never runs a second chain
    // beside an orphaned one. The arm then stops on the controller's
    // SAFETY_STATUS deadline.
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(126);  // the launcher died before prctl
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    sigprocmask(SIG_SETMASK, &old_mask, nullptr);
    if (!p.spec.log_path.empty()) {
      const int fd = open(p.spec.log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      if (fd >= 0) {
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
        close(fd);
      }
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  setpgid(pid, pid);  // also from the parent: no race with a quick stop
  p.pid = pid;
  p.state = ProcessState::kRunning;
  p.starts++;
  report_(p.spec.name + ": running (pid " + std::to_string(pid) + ")" +
          (p.starts > 1 ? ", start " + std::to_string(p.starts) : ""));
}

void ProcessGroup::start_all(int64_t now_us) {
  for (auto& p : processes_) start(*p, now_us);
}

void ProcessGroup::poll(int64_t now_us) {
  for (auto& p : processes_) {
    if (p->state == ProcessState::kRunning) {
      int status = 0;
      if (waitpid(p->pid, &status, WNOHANG) != p->pid) continue;
      kill(-p->pid, SIGKILL);  // leave none of its children behind
      p->last_exit = describe_exit(status);
      p->pid = -1;
      const auto delay_us = p->restarts.on_exit(now_us);
      if (!delay_us) {
        p->state = ProcessState::kGaveUp;
        report_(p->spec.name + ": " + p->last_exit + "; crashed " +
                std::to_string(p->restarts.recent_restarts()) + " times recently: left stopped" +
                (p->spec.required ? " (REQUIRED: the arm stays stopped)" : ""));
        continue;
      }
      p->state = ProcessState::kWaitingToRestart;
      p->restart_at_us = now_us + *delay_us;
      report_(p->spec.name + ": " + p->last_exit + "; restarting in " + std::to_string(*delay_us / 1000) +
              " ms (restart " + std::to_string(p->restarts.recent_restarts()) + ")");
    } else if (p->state == ProcessState::kWaitingToRestart && now_us >= p->restart_at_us) {
      start(*p, now_us);
    }
  }
}

void ProcessGroup::stop_all(int grace_ms) {
  bool any = false;
  for (auto& p : processes_) {
    if (p->state == ProcessState::kRunning) {
      kill(-p->pid, SIGTERM);
      any = true;
    } else if (p->state == ProcessState::kWaitingToRestart) {
      p->state = ProcessState::kStopped;
    }
  }
  if (!any) return;
  const int64_t deadline_us = monotonic_us() + int64_t{grace_ms} * 1000;
  while (true) {
    bool left = false;
    for (auto& p : processes_) {
      if (p->state != ProcessState::kRunning) continue;
      int status = 0;
      if (waitpid(p->pid, &status, WNOHANG) == p->pid) {
        kill(-p->pid, SIGKILL);  // its children, if any stayed
        p->last_exit = describe_exit(status);
        p->state = ProcessState::kStopped;
        p->pid = -1;
      } else if (monotonic_us() > deadline_us) {
        report_(p->spec.name + ": did not stop within " + std::to_string(grace_ms) + " ms: SIGKILL");
        kill(-p->pid, SIGKILL);
        waitpid(p->pid, &status, 0);
        p->last_exit = describe_exit(status);
        p->state = ProcessState::kStopped;
        p->pid = -1;
      } else {
        left = true;
      }
    }
    if (!left) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));  // poll interval of the reaper
  }
}

std::string ProcessGroup::status_table() const {
  std::ostringstream s;
  for (const auto& p : processes_) {
    s << "  " << p->spec.name << (p->spec.required ? "" : " (optional)") << ": " << state_name(p->state);
    if (p->pid > 0) s << ", pid " << p->pid;
    s << ", starts " << p->starts << ", last exit: " << p->last_exit << "\n";
  }
  return s.str();
}

std::vector<pid_t> ProcessGroup::running_pids() const {
  std::vector<pid_t> pids;
  for (const auto& p : processes_) {
    if (p->state == ProcessState::kRunning) pids.push_back(p->pid);
  }
  return pids;
}

bool ProcessGroup::any_required_gave_up() const {
  for (const auto& p : processes_) {
    if (p->spec.required && p->state == ProcessState::kGaveUp) return true;
  }
  return false;
}

}  // namespace tofguard::launch
