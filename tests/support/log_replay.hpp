#pragma once
// Replaying an input log (TOF_DEPTH, JOINT_STATE, CAMERA_POSE) with the real
// lcm-logplayer into the observer chain only (tofguard-renderer,
// tofguard-discrepancy, tofguard-risk, tofguard-intervene, started fresh),
// its outputs recorded with the real lcm-logger and read back
// (docs/replay.md): for replay_test and tune_replay_test. Run inside the
// test's private network namespace (NETNS), alone (SERIAL): the chain keeps
// real-time deadlines while the log plays.
//
// The latched start: tofguard-intervene starts stopped and allows motion
// only after an accepted reset, which it accepts only while the risk is
// SAFE. Replay runs tofguard-reset, as an operator would, once three
// frames in a row were judged SAFE.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "tofguard/common/process.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/sim_camera_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"
#include "tool_support.hpp"

namespace tofguard::test {

// The start of every log that lcm-logplayer 1.3.1 may drop (it reads before
// it subscribes its republisher) and the chain spends starting up: frames
// captured in it are not judged by these tests.
inline constexpr int64_t kLeadInUs = 500'000;
// Frame verdicts in a row before the test asks for the reset.
inline constexpr int kSafeFramesBeforeReset = 3;

inline const std::vector<std::string> kChain = {"tofguard-intervene", "tofguard-risk", "tofguard-discrepancy",
                                                "tofguard-renderer"};

// lcm-logplayer's speed: 1, or TOFGUARD_REPLAY_SPEED to measure whether
// faster replays hold up (docs/replay.md: at 2 they do not).
inline std::string replay_speed() {
  const char* speed = std::getenv("TOFGUARD_REPLAY_SPEED");
  return speed && *speed ? speed : "1";
}

// A program in PATH ("" when absent).
inline std::string in_path(const std::string& program) {
  std::istringstream path(std::getenv("PATH") ? std::getenv("PATH") : "");
  for (std::string dir; std::getline(path, dir, ':');) {
    const std::string candidate = dir + "/" + program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

template <typename Message>
inline std::optional<Message> decode(const lcm::LogEvent& event) {
  Message m;
  if (m.decode(event.data, 0, event.datalen) < 0) return std::nullopt;
  return m;
}

struct Frame {
  int64_t seq = 0;
  int64_t utime = 0;        // capture time, from the log
  int64_t received_us = 0;  // the lcm-logger receive time
  size_t depth_hash = 0;    // of depth_mm: a frozen camera repeats it
};

inline Frame frame_of(const depth_image_t& d, int64_t received_us) {
  const std::string_view bytes(reinterpret_cast<const char*>(d.depth_mm.data()),
                               d.depth_mm.size() * sizeof(int16_t));
  return {d.seq, d.utime, received_us, std::hash<std::string_view>{}(bytes)};
}

struct Verdict {
  int64_t seq = 0;
  int8_t level = 0;
  int8_t cause = 0;
  std::string suspect;
  std::string detail;
  int64_t received_us = 0;
  // What must be the same on every replay.
  std::string key() const {
    return std::to_string(seq) + " " + risk_level_name(level) + " " + risk_cause_name(cause) + " '" +
           suspect + "'";
  }
};

struct Status {
  bool motion_allowed = false;
  int8_t cause = 0;
  std::string reason;
  int64_t received_us = 0;
};

// What a log under tests/data holds.
struct InputLog {
  std::vector<Frame> frames;  // TOF_DEPTH (received_us: the recording's)
  // Every camera's frames (TOF_DEPTH and, with several cameras,
  // TOF_DEPTH/<id>), by the camera id they carry.
  std::map<std::string, std::vector<Frame>> frames_of_camera;
  int64_t first_event_us = 0;
  // The fault's injection time (SIM_JOINT_FAULT / SIM_CAMERA_FAULT utime);
  // -1 for the nominal log.
  int64_t fault_utime = -1;
  // The frames captured after the lead-in: those the tests judge.
  std::set<int64_t> judged_seqs() const { return judged_seqs_of(frames); }
  std::set<int64_t> judged_seqs(const std::string& camera_id) const {
    const auto it = frames_of_camera.find(camera_id);
    return it == frames_of_camera.end() ? std::set<int64_t>{} : judged_seqs_of(it->second);
  }

 private:
  std::set<int64_t> judged_seqs_of(const std::vector<Frame>& camera_frames) const {
    std::set<int64_t> seqs;
    for (const Frame& f : camera_frames) {
      if (f.received_us >= first_event_us + kLeadInUs) seqs.insert(f.seq);
    }
    return seqs;
  }
};

// A channel of any camera: `base` (the first camera's, e.g. TOF_DEPTH) or
// `base`/<id> (another camera's).
inline bool is_camera_channel(const std::string& channel, const std::string& base) {
  return channel == base || channel.rfind(base + "/", 0) == 0;
}

inline InputLog read_input_log(const std::string& path) {
  InputLog log;
  lcm::LogFile file(path, "r");
  EXPECT_TRUE(file.good()) << path;
  const ChannelNames defaults;
  bool first = true;
  while (const lcm::LogEvent* e = file.readNextEvent()) {
    if (first) log.first_event_us = e->timestamp;
    first = false;
    if (is_camera_channel(e->channel, defaults.depth)) {
      if (auto d = decode<depth_image_t>(*e)) {
        if (e->channel == defaults.depth) log.frames.push_back(frame_of(*d, e->timestamp));
        log.frames_of_camera[d->camera_id].push_back(frame_of(*d, e->timestamp));
      }
    } else if (e->channel == defaults.sim_joint_fault) {
      if (auto f = decode<sim_joint_fault_t>(*e)) log.fault_utime = f->utime;
    } else if (is_camera_channel(e->channel, defaults.sim_camera_fault)) {
      if (auto f = decode<sim_camera_fault_t>(*e)) log.fault_utime = f->utime;
    }
  }
  return log;
}

// What the replay's lcm-logger recorded.
struct ReplayOutput {
  std::vector<Frame> frames;  // TOF_DEPTH as replayed
  // Every camera's frames as replayed, and the seqs of its discrepancies
  // (SAFETY_DISCREPANCY, SAFETY_DISCREPANCY/<id>), by camera id.
  std::map<std::string, std::vector<Frame>> frames_of_camera;
  std::map<std::string, std::vector<int64_t>> discrepancy_seqs_of_camera;
  std::vector<Verdict> verdicts;  // SAFETY_RISK for camera frames
  std::vector<Verdict> timeouts;  // SAFETY_RISK with seq -1
  std::vector<Status> statuses;   // SAFETY_STATUS
  int64_t first_input_us = 0;     // the first replayed TOF_DEPTH or JOINT_STATE
  int64_t last_input_us = 0;      // the last one
  bool reset_accepted = false;

  std::map<int64_t, std::vector<const Verdict*>> verdicts_by_seq() const {
    std::map<int64_t, std::vector<const Verdict*>> by_seq;
    for (const Verdict& v : verdicts) by_seq[v.seq].push_back(&v);
    return by_seq;
  }
  // When motion was first allowed (-1: never).
  int64_t first_allowed_us() const {
    for (const Status& s : statuses) {
      if (s.motion_allowed) return s.received_us;
    }
    return -1;
  }
  // The first withdrawal after motion was allowed.
  const Status* first_stop() const {
    bool allowed = false;
    for (const Status& s : statuses) {
      if (s.motion_allowed) allowed = true;
      if (allowed && !s.motion_allowed) return &s;
    }
    return nullptr;
  }
  // The first DANGEROUS verdict (frame or timeout) received at or after `us`.
  const Verdict* first_dangerous_since(int64_t us) const {
    const Verdict* first = nullptr;
    for (const auto* list : {&verdicts, &timeouts}) {
      for (const Verdict& v : *list) {
        if (v.level == risk_t::DANGEROUS && v.received_us >= us &&
            (!first || v.received_us < first->received_us)) {
          first = &v;
        }
      }
    }
    return first;
  }
};

inline ReplayOutput read_output_log(const std::string& path, const deployment::Config& config) {
  ReplayOutput out;
  lcm::LogFile file(path, "r");
  EXPECT_TRUE(file.good()) << path;
  while (const lcm::LogEvent* e = file.readNextEvent()) {
    if (is_camera_channel(e->channel, config.channels.depth)) {
      if (auto d = decode<depth_image_t>(*e)) {
        if (e->channel == config.channels.depth) out.frames.push_back(frame_of(*d, e->timestamp));
        out.frames_of_camera[d->camera_id].push_back(frame_of(*d, e->timestamp));
      }
      if (out.first_input_us == 0) out.first_input_us = e->timestamp;
      out.last_input_us = e->timestamp;
    } else if (is_camera_channel(e->channel, config.channels.discrepancy)) {
      if (auto d = decode<discrepancy_t>(*e)) out.discrepancy_seqs_of_camera[d->camera_id].push_back(d->seq);
    } else if (e->channel == config.channels.joint_state) {
      if (out.first_input_us == 0) out.first_input_us = e->timestamp;
      out.last_input_us = e->timestamp;
    } else if (e->channel == config.channels.risk) {
      if (auto r = decode<risk_t>(*e)) {
        Verdict v{r->seq, r->level, r->cause, r->suspect, r->detail, e->timestamp};
        (r->seq >= 0 ? out.verdicts : out.timeouts).push_back(v);
      }
    } else if (e->channel == config.channels.status) {
      if (auto s = decode<safety_status_t>(*e)) {
        out.statuses.push_back({s->motion_allowed != 0, s->cause, s->reason, e->timestamp});
      }
    }
  }
  return out;
}

// One replay of `log` into a freshly started observer chain.
class Replay {
 public:
  // `config_path`: the replay config (scripts/record-scenario --write-config
  // --replay), which every process of the chain and tofguard-reset read.
  Replay(const std::string& log, const std::string& run_name, const std::string& config_path)
      : config_path_(config_path),
        config_(deployment::load_config(config_path, nullptr)),
        lcm_(config_.lcm.url) {
    output_log_ = output_dir() + "/" + run_name + ".lcmlog";
    std::filesystem::remove(output_log_);
    lcm_.subscribe(config_.channels.heartbeat, &Replay::on_heartbeat, this);
    lcm_.subscribe(config_.channels.risk, &Replay::on_risk, this);
    // The outputs, and the inputs as replayed (for the replay's timeline).
    logger_ = std::make_unique<Subprocess>(
        run_name + "-lcm-logger",
        std::vector<std::string>{in_path("lcm-logger"), "-q", "-f", "--flush-interval=20", "-c",
                                 "(SAFETY_.*|TOF_DEPTH|JOINT_STATE|CAMERA_POSE)(/.*)?",
                                 "--lcm-url=" + config_.lcm.url, output_log_});
    start_chain(run_name);
    // Ready: every process beats, and the logger writes (the heartbeats).
    const bool ready = wait_until(
        [&] {
          return heartbeats_.size() == chain_.size() && std::filesystem::exists(output_log_) &&
                 std::filesystem::file_size(output_log_) > 0;
        },
        std::chrono::seconds(20), [&] { lcm_.handleTimeout(5); });
    EXPECT_TRUE(ready) << "the chain or lcm-logger did not start:\n" << stderr_of_all();
    const std::string lcm_url_arg = "--lcm-url=" + config_.lcm.url;
    player_ = std::make_unique<Subprocess>(
        run_name + "-lcm-logplayer",
        std::vector<std::string>{in_path("lcm-logplayer"), "-s", replay_speed(), lcm_url_arg, log});
    const InputLog input = read_input_log(log);
    const int64_t last_seq = input.frames.empty() ? -1 : input.frames.back().seq;
    // The log plays; the reset once the chain judges frames SAFE.
    EXPECT_TRUE(wait_until([&] { return !player_->running(); }, std::chrono::seconds(60), [&] { pump(); }))
        << "lcm-logplayer did not finish";
    EXPECT_EQ(player_->wait(std::chrono::seconds(1)), 0) << player_->stderr_text();
    // The last frame's verdict (at most the pairing timeout later).
    wait_until([&] { return last_judged_seq_ >= last_seq; }, std::chrono::seconds(2), [&] { pump(); });
    // lcm-logger receives on its own socket: seeing the verdict here does not
    // mean it has written it yet. Stop it only once three heartbeats sent
    // after the verdict (same URL, so behind it in every receiver's queue)
    // have arrived here, i.e. at least 100 ms later.
    const int beats_at_last_verdict = heartbeats_seen_;
    wait_until(
        [&] { return heartbeats_seen_ >= beats_at_last_verdict + 3 * static_cast<int>(chain_.size()); },
        std::chrono::seconds(2), [&] { pump(); });
    logger_->signal(SIGINT);
    EXPECT_EQ(logger_->wait(std::chrono::seconds(5)), 0) << logger_->stderr_text();
    for (auto& p : chain_) p->signal(SIGTERM);
    for (auto& p : chain_) p->wait(std::chrono::seconds(5));
    output_ = read_output_log(output_log_, config_);
    output_.reset_accepted = reset_accepted_;
  }

  const ReplayOutput& output() const { return output_; }
  const deployment::Config& config() const { return config_; }
  std::string stderr_of_all() const {
    std::string text;
    for (const auto& p : chain_) text += p->stderr_text();
    return text;
  }

 private:
  // kChain's processes; with several cameras a process of one camera
  // (per_camera_process_names) once per camera, with --camera ID.
  void start_chain(const std::string& run_name) {
    const std::vector<std::string>& per_camera = per_camera_process_names();
    for (const std::string& name : kChain) {
      const std::vector<std::string> argv = {bin_dir() + "/" + name, "--config", config_path_};
      const bool of_a_camera = std::find(per_camera.begin(), per_camera.end(), name) != per_camera.end();
      if (!of_a_camera || config_.cameras.size() < 2) {
        chain_.push_back(std::make_unique<Subprocess>(run_name + "-" + name, argv));
        continue;
      }
      for (const deployment::CameraSection& camera : config_.cameras) {
        std::vector<std::string> with_camera = argv;
        with_camera.insert(with_camera.end(), {"--camera", camera.id});
        chain_.push_back(std::make_unique<Subprocess>(run_name + "-" + name + "-" + camera.id, with_camera));
      }
    }
  }

  void pump() {
    lcm_.handleTimeout(2);
    if (reset_ && !reset_->running()) {
      reset_accepted_ = reset_->wait(std::chrono::milliseconds(0)) == 0;
      reset_.reset();
      safe_streak_ = 0;
    }
    if (!reset_accepted_ && !reset_ && safe_streak_ >= kSafeFramesBeforeReset) {
      reset_ = std::make_unique<Subprocess>(
          "replay-reset",
          std::vector<std::string>{bin_dir() + "/tofguard-reset", "--config", config_path_, "--who",
                                   "replay_test", "--why", "start of the replay", "--timeout-ms", "1000"});
    }
  }
  void on_heartbeat(const lcm::ReceiveBuffer*, const std::string&, const heartbeat_t* hb) {
    heartbeats_.insert(hb->process);
    ++heartbeats_seen_;
  }
  void on_risk(const lcm::ReceiveBuffer*, const std::string&, const risk_t* r) {
    if (r->seq < 0) return;
    last_judged_seq_ = std::max(last_judged_seq_, r->seq);
    safe_streak_ = r->level == risk_t::SAFE ? safe_streak_ + 1 : 0;
  }

  std::string config_path_;
  deployment::Config config_;
  lcm::LCM lcm_;
  std::string output_log_;
  std::unique_ptr<Subprocess> logger_;
  std::vector<std::unique_ptr<Subprocess>> chain_;
  std::unique_ptr<Subprocess> player_;
  std::unique_ptr<Subprocess> reset_;
  std::set<std::string> heartbeats_;
  int safe_streak_ = 0;
  int heartbeats_seen_ = 0;
  int64_t last_judged_seq_ = -1;
  bool reset_accepted_ = false;
  ReplayOutput output_;
};

// Every judged frame was replayed and got exactly one verdict (one failure
// each, naming the frames).
inline void expect_every_frame_judged_once(const InputLog& input, const ReplayOutput& out) {
  std::set<int64_t> replayed;
  for (const Frame& f : out.frames) replayed.insert(f.seq);
  const auto by_seq = out.verdicts_by_seq();
  std::string not_replayed, not_judged_once;
  for (int64_t seq : input.judged_seqs()) {
    if (!replayed.count(seq)) not_replayed += " " + std::to_string(seq);
    const auto it = by_seq.find(seq);
    const size_t verdicts = it == by_seq.end() ? 0 : it->second.size();
    if (verdicts != 1) not_judged_once += " " + std::to_string(seq) + " (" + std::to_string(verdicts) + ")";
  }
  EXPECT_EQ(not_replayed, "") << "frames of the log that never arrived (a machine too busy for real time?)";
  EXPECT_EQ(not_judged_once, "") << "frames without exactly one verdict (seq (verdicts))";
}

// With several cameras: every judged frame of each camera was replayed and
// got exactly one discrepancy of that camera (one failure each, naming the
// camera and the frames), and every discrepancy one verdict: a frame
// verdict, except while a camera has had no frame judged yet and the worst
// camera's latest verdict is its timeout (seq -1; VerdictFusion), at most
// once per camera at the start.
inline void expect_every_camera_frame_judged_once(const InputLog& input, const ReplayOutput& out) {
  size_t discrepancies = 0;
  for (const auto& [camera_id, frames] : input.frames_of_camera) {
    std::set<int64_t> replayed;
    if (out.frames_of_camera.count(camera_id)) {
      for (const Frame& f : out.frames_of_camera.at(camera_id)) replayed.insert(f.seq);
    }
    std::map<int64_t, int> judged;
    if (out.discrepancy_seqs_of_camera.count(camera_id)) {
      for (int64_t seq : out.discrepancy_seqs_of_camera.at(camera_id)) ++judged[seq];
      discrepancies += out.discrepancy_seqs_of_camera.at(camera_id).size();
    }
    std::string not_replayed, not_judged_once;
    for (int64_t seq : input.judged_seqs(camera_id)) {
      if (!replayed.count(seq)) not_replayed += " " + std::to_string(seq);
      if (judged[seq] != 1)
        not_judged_once += " " + std::to_string(seq) + " (" + std::to_string(judged[seq]) + ")";
    }
    EXPECT_EQ(not_replayed, "") << camera_id << ": frames of the log that never arrived";
    EXPECT_EQ(not_judged_once, "") << camera_id
                                   << ": frames without exactly one discrepancy (seq (discrepancies))";
  }
  EXPECT_GE(input.frames_of_camera.size(), 2u);
  EXPECT_LE(out.verdicts.size(), discrepancies) << "more frame verdicts than discrepancies";
  EXPECT_GE(out.verdicts.size() + input.frames_of_camera.size(), discrepancies)
      << "discrepancies without their frame verdict";
}

inline std::string describe(const ReplayOutput& out) {
  std::string text;
  for (const Verdict& v : out.verdicts) text += "  " + v.key() + " | " + v.detail + "\n";
  if (const Status* stop = out.first_stop()) text += "  first stop: " + stop->reason + "\n";
  return text;
}

}  // namespace tofguard::test
