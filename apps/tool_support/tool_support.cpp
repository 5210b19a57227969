#include "tool_support.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace tofguard::test {

std::string source_dir() { return TOFGUARD_SOURCE_DIR; }
std::string binary_dir() { return TOFGUARD_BINARY_DIR; }
std::string bin_dir() { return std::string(TOFGUARD_BINARY_DIR) + "/bin"; }
std::string output_dir() { return std::string(TOFGUARD_BINARY_DIR) + "/test-output"; }
std::string shared_dir() {
  const auto dir = std::filesystem::path(TOFGUARD_SOURCE_DIR).parent_path() / "shared";
  return std::filesystem::is_directory(dir) ? dir.string() : std::string();
}

bool wait_until(const std::function<bool()>& condition, std::chrono::milliseconds deadline,
                const std::function<void()>& poll) {
  const auto end = std::chrono::steady_clock::now() + deadline;
  while (true) {
    if (condition()) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    if (poll) {
      poll();
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
}

Subprocess::Subprocess(const std::string& name, const std::vector<std::string>& argv) {
  std::filesystem::create_directories(output_dir());
  stdout_path_ = output_dir() + "/" + name + ".stdout";
  stderr_path_ = output_dir() + "/" + name + ".stderr";
  // Emptied here, before the child starts: a test that polls the output
  // must never read an earlier run's text (the child truncates them only
  // once it runs).
  std::ofstream(stdout_path_, std::ios::trunc);
  std::ofstream(stderr_path_, std::ios::trunc);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t parent = getpid();
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    // The child dies with the test: a test killed by ctest's timeout (only
    // the test process gets the SIGKILL), by Ctrl-C (the child has its own
    // process group, so the terminal's SIGINT misses it) or by a crash
    // runs no destructor, and would leave its processes running.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(125);  // the test died before prctl
    const int out = open(stdout_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(stderr_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out < 0 || err < 0) _exit(126);
    dup2(out, STDOUT_FILENO);
    dup2(err, STDERR_FILENO);
    setpgid(0, 0);  // its own process group, so kill() reaches its children
    execv(args[0], args.data());
    _exit(127);
  }
}

Subprocess::~Subprocess() {
  if (running()) {
    kill(-pid_, SIGKILL);
    kill(pid_, SIGKILL);
    wait(std::chrono::milliseconds(5000));
  }
}

bool Subprocess::running() {
  if (exit_code_ >= 0 || pid_ <= 0) return false;
  int status = 0;
  const pid_t r = waitpid(pid_, &status, WNOHANG);
  if (r == pid_) {
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return false;
  }
  return r == 0;
}

void Subprocess::signal(int signo) {
  if (running()) kill(pid_, signo);
}

int Subprocess::wait(std::chrono::milliseconds deadline) {
  wait_until([this] { return !running(); }, deadline);
  return exit_code_;
}

std::string Subprocess::stdout_text() const { return read_file(stdout_path_); }
std::string Subprocess::stderr_text() const { return read_file(stderr_path_); }

int run_command(const std::string& name, const std::vector<std::string>& argv, std::string* stdout_text,
                std::string* stderr_text) {
  Subprocess p(name, argv);
  const int code = p.wait(std::chrono::seconds(60));
  if (stdout_text) *stdout_text = p.stdout_text();
  if (stderr_text) *stderr_text = p.stderr_text();
  return code;
}

void erase_config_section(std::string* text, const std::string& key) {
  const auto start = text->find("\n" + key + ":");
  if (start == std::string::npos) return;
  size_t end = start + 1;
  while ((end = text->find('\n', end)) != std::string::npos && end + 1 < text->size() &&
         ((*text)[end + 1] == ' ' || (*text)[end + 1] == '\n' || (*text)[end + 1] == '#')) {
    ++end;
  }
  text->erase(start, end == std::string::npos ? std::string::npos : end - start);
}

std::string sim_config_variant(const std::string& name,
                               const std::vector<std::pair<std::string, std::string>>& replacements,
                               const std::string& appended) {
  return config_variant(source_dir() + "/config/sim.yaml", name, replacements, appended);
}

std::string config_variant(const std::string& base_path, const std::string& name,
                           const std::vector<std::pair<std::string, std::string>>& replacements,
                           const std::string& appended) {
  std::string text = read_file(base_path);
  for (const auto& [from, to] : replacements) {
    const auto at = text.find(from);
    if (at == std::string::npos) throw std::runtime_error(base_path + " no longer contains: " + from);
    text.replace(at, from.size(), to);
  }
  const std::string models = source_dir() + "/config/models/";
  for (size_t p = text.find("models/"); p != std::string::npos;
       p = text.find("models/", p + models.size() + 1)) {
    if (p > 0 && text[p - 1] == '/') continue;
    text.replace(p, 7, models);
  }
  // The camera profiles (discrepancy's, or each of a cameras list's), by
  // absolute path.
  const std::string profile_key = "\n  camera_profile: ";
  for (auto at = text.find(profile_key); at != std::string::npos; at = text.find(profile_key, at + 1)) {
    if (text[at + profile_key.size()] != '/') text.insert(at + profile_key.size(), source_dir() + "/config/");
  }
  // The embedded default's key (made by scripts/build), by absolute path.
  const std::string key_line = "key_file: auth.key";
  if (const auto at = text.find(key_line); at != std::string::npos) {
    text.replace(at, key_line.size(), "key_file: " + source_dir() + "/config/auth.key");
  }
  // A top-level section in `appended` replaces sim.yaml's own; "key: ~"
  // removes it.
  std::stringstream added(appended);
  std::string kept;
  for (std::string line; std::getline(added, line);) {
    const bool removes = line.size() > 3 && line[0] != ' ' && line.compare(line.size() - 3, 3, ": ~") == 0;
    if (!removes) kept += line + "\n";
    if (line.empty() || line[0] == ' ' || line[0] == '#' || line.find(':') == std::string::npos) continue;
    erase_config_section(&text, line.substr(0, line.find(':')));
  }
  text += appended.empty() ? appended : kept;
  const std::string path = output_dir() + "/" + name + ".yaml";
  write_file(path, text);
  return path;
}

std::string config_line(const std::string& text, const std::string& prefix) {
  const auto at = text.find("\n" + prefix);
  if (at == std::string::npos || text.find("\n" + prefix, at + 1) != std::string::npos) {
    throw std::runtime_error("the config no longer contains exactly one line starting with: " + prefix);
  }
  size_t end = text.find('\n', at + 1);
  if (text.substr(at, end - at).find('{') != std::string::npos) end = text.find("}\n", at) + 1;
  return text.substr(at + 1, end - at);
}

std::vector<std::pair<std::string, std::string>> ideal_camera_replacements() {
  const std::string text = read_file(source_dir() + "/config/sim.yaml");
  return {{config_line(text, "    residual: {"), ""},
          {config_line(text, "  camera_profile: "), ""},
          {config_line(text, "  noise: {sigma_at_0m_mm: "),
           "  noise: {sigma_at_0m_mm: 4.0, sigma_per_m2_mm: 1.2}\n"},
          {config_line(text, "    static_bias_mm: "), "    static_bias_mm: 0\n"},
          {config_line(text, "    fixed_pattern_sigma_mm: "), "    fixed_pattern_sigma_mm: 0\n"},
          {config_line(text, "    silhouette_allowance: "), ""}};
}

std::string ideal_camera_config(const std::string& name,
                                const std::vector<std::pair<std::string, std::string>>& replacements) {
  std::vector<std::pair<std::string, std::string>> all = ideal_camera_replacements();
  all.insert(all.end(), replacements.begin(), replacements.end());
  return sim_config_variant(name + "-" + std::to_string(::getpid()), all);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_file(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream out(path, std::ios::binary);
  out << text;
}

}  // namespace tofguard::test
