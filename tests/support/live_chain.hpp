#pragma once
// The whole safety chain as real processes (the simulated arm and camera,
// tofguard-renderer, -discrepancy, -risk, -intervene and -estimator) over
// real LCM in the test's private network namespace, watched from the test:
// SAFETY_STATUS, SAFETY_POWER, SAFETY_RISK and the heartbeats, with their
// arrival times on the test's monotonic clock. For the fault-injection and
// soak tests (tests/system); safety_chain_e2e_test has its own, richer one.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <chrono>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "recovery_deadline.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/process.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/power_relay_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tool_support.hpp"

namespace tofguard::test {

// In the order they are started: the judge before its inputs.
inline const std::vector<std::string>& chain_process_names() {
  static const std::vector<std::string> names = {
      "tofguard-intervene",  "tofguard-risk",   "tofguard-discrepancy", "tofguard-renderer",
      "tofguard-joints-sim", "tofguard-camera", "tofguard-estimator"};
  return names;
}

// The processes of `config`'s chain, in chain_process_names() order: a
// process of one camera (per_camera_process_names) once per camera, named
// with the camera's suffix ("tofguard-renderer/tof-side"), the others once.
inline std::vector<std::string> chain_processes_of(const deployment::Config& config) {
  std::vector<std::string> names;
  const std::vector<std::string>& per_camera = per_camera_process_names();
  for (const std::string& p : chain_process_names()) {
    if (std::find(per_camera.begin(), per_camera.end(), p) == per_camera.end()) {
      names.push_back(p);
      continue;
    }
    for (const deployment::CameraSection& camera : config.cameras) names.push_back(p + camera.name_suffix);
  }
  return names;
}

// With several cameras, the camera a fused verdict came from: its detail's
// "<id>: " prefix (risk/verdict_fusion.hpp).
inline std::string verdict_camera(const risk_t& r) {
  const auto colon = r.detail.find(": ");
  return colon == std::string::npos ? "" : r.detail.substr(0, colon);
}

class LiveChain {
 public:
  // A config already written (e.g. ideal_camera_config's).
  struct ConfigFile {
    explicit ConfigFile(std::string config_path) : path(std::move(config_path)) {}
    std::string path;
  };
  // config/sim.yaml as sim_config_variant(name, replacements, appended);
  // starts every process of chain_process_names() unless `start` is false.
  explicit LiveChain(const std::string& name,
                     const std::vector<std::pair<std::string, std::string>>& replacements = {},
                     bool start = true)
      : LiveChain(name, ConfigFile{sim_config_variant(name, replacements)}, start) {}
  LiveChain(const std::string& name, const ConfigFile& config_file, bool start)
      : name_(name),
        config_path_(config_file.path),
        config_(deployment::load_config(config_path_, nullptr)),
        safety_(config_.lcm.url),
        images_(config_.lcm.image_url) {
    safety_.subscribe(config_.channels.status, &LiveChain::on_status, this);
    safety_.subscribe(config_.channels.power, &LiveChain::on_power, this);
    safety_.subscribe(config_.channels.risk, &LiveChain::on_risk, this);
    safety_.subscribe(config_.channels.heartbeat, &LiveChain::on_heartbeat, this);
    if (start) {
      for (const std::string& p : chain_processes_of(config_)) this->start(p);
    }
  }

  // `process` as chain_processes_of names it: with several cameras a
  // process of one camera is started with --camera (the first camera's for
  // a name without a suffix).
  void start(const std::string& process) {
    const std::string binary = process.substr(0, process.find('/'));
    std::vector<std::string> argv;
    if (const auto prefix = argv_prefix.find(process); prefix != argv_prefix.end()) argv = prefix->second;
    argv.insert(argv.end(), {bin_dir() + "/" + binary, "--config", config_path_});
    const std::vector<std::string>& per_camera = per_camera_process_names();
    if (config_.cameras.size() > 1 &&
        std::find(per_camera.begin(), per_camera.end(), binary) != per_camera.end()) {
      const auto slash = process.find('/');
      argv.insert(argv.end(), {"--camera", slash == std::string::npos ? config_.cameras.front().id
                                                                      : process.substr(slash + 1)});
    }
    if (const auto more = arguments.find(process); more != arguments.end()) {
      argv.insert(argv.end(), more->second.begin(), more->second.end());
    }
    std::string file_name = process;  // the output files' name: no '/'
    std::replace(file_name.begin(), file_name.end(), '/', '@');
    processes_[process] =
        std::make_unique<Subprocess>(name_ + "-" + file_name + "-" + std::to_string(++starts_), argv);
  }
  // Arguments after --config FILE, by process (e.g. tofguard-joints-sim's
  // --task), for the processes started after they are set.
  std::map<std::string, std::vector<std::string>> arguments;
  // Commands a process is started through, by process (e.g.
  // SecondHost::argv_prefix(): on another host).
  std::map<std::string, std::vector<std::string>> argv_prefix;
  Subprocess& process(const std::string& name) { return *processes_.at(name); }
  std::string stderr_of_all() {
    std::string text;
    for (auto& [name, p] : processes_) {
      const std::string err = p->stderr_text();
      text += "--- " + name + ":\n" + (err.size() > 3000 ? err.substr(err.size() - 3000) : err);
    }
    return text;
  }

  // Handles what has arrived, waiting at most 1 ms.
  void pump() {
    while (safety_.handleTimeout(0) > 0) {
    }
    safety_.handleTimeout(1);
    if (on_pump) on_pump();
  }
  bool wait(const std::function<bool()>& condition, std::chrono::milliseconds deadline) {
    return wait_until(condition, deadline, [this] { pump(); });
  }

  // Waits for 15 SAFE frame verdicts in a row, then resets (tofguard-reset)
  // until accepted and motion is allowed.
  void bring_to_motion(const std::string& why) {
    safe_streak_ = 0;
    const int64_t waiting_since_us = monotonic_us();
    ASSERT_TRUE(wait([&] { return safe_streak_ >= 15; }, kRecoveryDeadline))
        << "never SAFE: last risk " << describe_last_risk() << "\n"
        << stderr_of_all();
    std::cout << "15 SAFE verdicts in a row " << (monotonic_us() - waiting_since_us) / 1000
              << " ms after the wait began (" << why << ")" << std::endl;
    std::string out;
    int code = -1;
    for (int attempt = 0; attempt < 5 && code != 0; ++attempt) {
      code = run_command(
          name_ + "-reset",
          {bin_dir() + "/tofguard-reset", "--config", config_path_, "--who", "test", "--why", why}, &out);
      pump();
    }
    ASSERT_EQ(code, 0) << out << " last risk " << describe_last_risk();
    ASSERT_TRUE(wait([&] { return motion_allowed_; }, std::chrono::seconds(2)));
  }

  // The monotonic time of the first SAFETY_STATUS with motion_allowed =
  // false that arrived after motion was allowed and after `since_us`
  // (-1: none yet).
  int64_t first_stop_since(int64_t since_us) const {
    for (const int64_t t : stop_arrivals_us_) {
      if (t >= since_us) return t;
    }
    return -1;
  }

  bool motion_allowed() const { return motion_allowed_; }
  int stops_seen() const { return static_cast<int>(stop_arrivals_us_.size()); }
  const std::vector<int64_t>& stop_arrivals_us() const { return stop_arrivals_us_; }
  int64_t statuses() const { return statuses_; }
  int64_t last_status_us() const { return last_status_us_; }
  const safety_status_t& last_status() const { return last_status_; }
  int64_t powers() const { return powers_; }
  int64_t last_power_us() const { return last_power_us_; }
  const power_relay_t& last_power() const { return last_power_; }
  int64_t frame_verdicts() const { return frame_verdicts_; }
  int64_t safe_verdicts() const { return safe_verdicts_; }
  const risk_t& last_risk() const { return last_risk_; }
  std::string describe_last_risk() const {
    return risk_level_name(last_risk_.level) + " " + risk_cause_name(last_risk_.cause) + " suspect '" +
           last_risk_.suspect + "' seq " + std::to_string(last_risk_.seq) + " | " + last_risk_.detail;
  }
  const std::map<std::string, heartbeat_t>& heartbeats() const { return heartbeats_; }
  const deployment::Config& config() const { return config_; }
  const std::string& config_path() const { return config_path_; }
  lcm::LCM& safety() { return safety_; }
  lcm::LCM& images() { return images_; }

  // Called by every pump() (e.g. to publish something periodically).
  std::function<void()> on_pump;
  // Called for every frame verdict (seq >= 0) as it arrives.
  std::function<void(const risk_t&)> on_frame_verdict;

 private:
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const safety_status_t* s) {
    const int64_t now = monotonic_us();
    if (motion_allowed_ && !s->motion_allowed) stop_arrivals_us_.push_back(now);
    motion_allowed_ = s->motion_allowed;
    last_status_ = *s;
    last_status_us_ = now;
    ++statuses_;
  }
  void on_power(const lcm::ReceiveBuffer*, const std::string&, const power_relay_t* p) {
    last_power_ = *p;
    last_power_us_ = monotonic_us();
    ++powers_;
  }
  void on_risk(const lcm::ReceiveBuffer*, const std::string&, const risk_t* r) {
    last_risk_ = *r;
    if (r->seq < 0) return;
    ++frame_verdicts_;
    if (r->level == risk_t::SAFE) ++safe_verdicts_;
    safe_streak_ = r->level == risk_t::SAFE ? safe_streak_ + 1 : 0;
    if (on_frame_verdict) on_frame_verdict(*r);
  }
  void on_heartbeat(const lcm::ReceiveBuffer*, const std::string&, const heartbeat_t* hb) {
    heartbeats_[hb->process] = *hb;
  }

  std::string name_;
  std::string config_path_;
  deployment::Config config_;
  lcm::LCM safety_;
  lcm::LCM images_;
  std::map<std::string, std::unique_ptr<Subprocess>> processes_;
  int starts_ = 0;
  bool motion_allowed_ = false;
  std::vector<int64_t> stop_arrivals_us_;
  int64_t statuses_ = 0;
  int64_t last_status_us_ = 0;
  safety_status_t last_status_{};
  int64_t powers_ = 0;
  int64_t last_power_us_ = 0;
  power_relay_t last_power_{};
  int64_t frame_verdicts_ = 0;
  int64_t safe_verdicts_ = 0;
  int safe_streak_ = 0;
  risk_t last_risk_{};
  std::map<std::string, heartbeat_t> heartbeats_;
};

}  // namespace tofguard::test
