#pragma once
// Shared test helpers: real subprocesses, waiting on a condition with a
// deadline (never a sleep as synchronisation), and the project's paths.
#include <sys/types.h>
#include <chrono>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace tofguard::test {

// Folders, fixed at build time.
std::string source_dir();  // the repository root
std::string binary_dir();  // the CMake build folder
std::string bin_dir();     // where the tofguard-* executables are
std::string output_dir();  // scratch space for test outputs
// ../shared beside the repository (public robot models), "" when absent.
std::string shared_dir();

// Calls `condition` until it returns true or `deadline` has passed; between
// calls it runs `poll` (e.g. LCM handleTimeout) or yields for 1 ms. Returns
// whether the condition became true.
bool wait_until(const std::function<bool()>& condition, std::chrono::milliseconds deadline,
                const std::function<void()>& poll = nullptr);

// A child process whose stdout and stderr go to files.
class Subprocess {
 public:
  // Starts argv[0] (a path) with argv; `name` names the output files in
  // output_dir(). The child gets SIGKILL when the thread that started it
  // ends (PR_SET_PDEATHSIG), so a test that is killed leaves nothing
  // running: start Subprocesses from the test's own thread.
  Subprocess(const std::string& name, const std::vector<std::string>& argv);
  ~Subprocess();  // kills the child (SIGKILL) if it still runs
  Subprocess(const Subprocess&) = delete;
  Subprocess& operator=(const Subprocess&) = delete;

  pid_t pid() const { return pid_; }
  bool running();
  void signal(int signo);
  // Waits for the child to exit; returns its exit code (128 + signal when
  // killed), or -1 if it was still running at the deadline.
  int wait(std::chrono::milliseconds deadline);
  std::string stdout_text() const;
  std::string stderr_text() const;

 private:
  pid_t pid_ = -1;
  int exit_code_ = -1;
  std::string stdout_path_;
  std::string stderr_path_;
};

// Runs a command to completion (deadline 60 s); returns its exit code and
// fills the outputs.
int run_command(const std::string& name, const std::vector<std::string>& argv,
                std::string* stdout_text = nullptr, std::string* stderr_text = nullptr);

// config/sim.yaml copied to output_dir()/<name>.yaml with `replacements`
// (each `from` must occur) applied and `appended` added at the end; the
// model, key and camera profile paths are made absolute so the copy works
// from anywhere. A top-level section in `appended` replaces sim.yaml's
// own; a line "<key>: ~" there removes sim.yaml's section `key` (an
// optional section absent, e.g. "occupant: ~"). Returns the copy's path.
// Erases the top-level section `key` of a config's `text` (its line, its
// indented lines and the blank and comment lines after them); nothing when
// there is none.
void erase_config_section(std::string* text, const std::string& key);

std::string sim_config_variant(const std::string& name,
                               const std::vector<std::pair<std::string, std::string>>& replacements = {},
                               const std::string& appended = "");
// As sim_config_variant, on another config of config/ (`base_path`, e.g.
// config/sim-two-cameras.yaml).
std::string config_variant(const std::string& base_path, const std::string& name,
                           const std::vector<std::pair<std::string, std::string>>& replacements = {},
                           const std::string& appended = "");

// The whole line of a config's `text` that starts with `prefix` (after a
// newline), with its newline; the mapping's continuation lines too when it
// opens a `{` that the line does not close. Throws unless there is exactly
// one.
std::string config_line(const std::string& text, const std::string& prefix);

// config/sim.yaml with its simulated camera ideal after its distance
// calibration, for the tests and tools that make their own frames or judge
// an ideal camera beside imperfect ones: no camera.sim.residual, no
// discrepancy.camera_profile, the ideal camera's noise as tofguard-tune
// fitted it (4.0 + 1.2 d^2 mm) and no static allowance. The lines are
// found by their keys, so a re-commissioned profile's values need no change
// here; a key that is gone throws. `replacements` as sim_config_variant's,
// applied after these; written as output_dir()/<name>-<pid>.yaml (tests
// run in parallel).
std::vector<std::pair<std::string, std::string>> ideal_camera_replacements();
std::string ideal_camera_config(const std::string& name = "ideal-camera",
                                const std::vector<std::pair<std::string, std::string>>& replacements = {});

std::string read_file(const std::string& path);
void write_file(const std::string& path, const std::string& text);

}  // namespace tofguard::test
