// Replay tests: the scenarios recorded from the simulator (tests/data, made
// by scripts/record-scenario) are replayed with the real lcm-logplayer into
// the observer chain only (tofguard-renderer, tofguard-discrepancy,
// tofguard-risk, tofguard-intervene; no simulator), the chain's outputs are
// recorded with the real lcm-logger, and that output log is checked:
// - nominal: after the start-up reset the permission to move holds until
//   the log ends, and no frame is judged DANGEROUS;
// - each fault: the permission is withdrawn with the expected cause (and
//   suspect) within the stop budget, measured on the replay's timeline: the
//   lcm-logger receive time of the status against that of the first
//   affected camera frame as replayed (one logger, one clock);
// - two replays of a log give the same frame verdicts (seq, level, cause,
//   suspect) for every camera frame after the log's lead-in.
//
// The latched start: tofguard-intervene starts stopped and allows motion
// only after an accepted reset, which it accepts only while the risk is
// SAFE. The test runs tofguard-reset, as an operator would, once three
// frames in a row were judged SAFE (in the nominal lead-in before a fault).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>
#include <lcm/lcm-cpp.hpp>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include "test_support.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/sim_camera_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"

namespace tofguard::test {
namespace {

// How long processing may add to the frames a fault needs before it is
// DANGEROUS (the e2e test's budget: 200 ms at 30 Hz for two frame periods,
// 133 ms of it processing; more here for a loaded 2-core machine).
constexpr int64_t kProcessingBudgetUs = 200'000;
// The start of every log that lcm-logplayer 1.3.1 may drop (it reads before
// it subscribes its republisher) and the chain spends starting up: frames
// captured in it are not judged by these tests.
constexpr int64_t kLeadInUs = 500'000;
// Frame verdicts in a row before the test asks for the reset.
constexpr int kSafeFramesBeforeReset = 3;

const std::vector<std::string> kChain = {"tofguard-intervene", "tofguard-risk", "tofguard-discrepancy",
                                         "tofguard-renderer"};

// lcm-logplayer's speed: 1, or TOFGUARD_REPLAY_SPEED to measure whether
// faster replays hold up (docs/replay.md: at 2 they do not).
std::string replay_speed() {
  const char* speed = std::getenv("TOFGUARD_REPLAY_SPEED");
  return speed && *speed ? speed : "1";
}

// A program in PATH ("" when absent).
std::string in_path(const std::string& program) {
  std::istringstream path(std::getenv("PATH") ? std::getenv("PATH") : "");
  for (std::string dir; std::getline(path, dir, ':');) {
    const std::string candidate = dir + "/" + program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

template <typename Message>
std::optional<Message> decode(const lcm::LogEvent& event) {
  Message m;
  if (m.decode(event.data, 0, event.datalen) < 0) return std::nullopt;
  return m;
}

// The replay config: config/sim.yaml made single-URL, at the recordings'
// camera rate, without tofguard-camera's heartbeat (scripts/record-scenario
// --write-config --replay, as docs/replay.md tells users).
const std::string& replay_config_path() {
  static const std::string path = [] {
    const std::string p = output_dir() + "/replay.yaml";
    std::string out, err;
    const int code =
        run_command("replay-write-config",
                    {"/bin/bash", source_dir() + "/scripts/record-scenario", "--write-config", p, "--replay"},
                    &out, &err);
    if (code != 0) throw std::runtime_error("record-scenario --write-config failed: " + out + err);
    return p;
  }();
  return path;
}

struct Frame {
  int64_t seq = 0;
  int64_t utime = 0;        // capture time, from the log
  int64_t received_us = 0;  // the lcm-logger receive time
  size_t depth_hash = 0;    // of depth_mm: a frozen camera repeats it
};

Frame frame_of(const depth_image_t& d, int64_t received_us) {
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
  int64_t first_event_us = 0;
  // The fault's injection time (SIM_JOINT_FAULT / SIM_CAMERA_FAULT utime);
  // -1 for the nominal log.
  int64_t fault_utime = -1;
  // The frames captured after the lead-in: those the tests judge.
  std::set<int64_t> judged_seqs() const {
    std::set<int64_t> seqs;
    for (const Frame& f : frames) {
      if (f.received_us >= first_event_us + kLeadInUs) seqs.insert(f.seq);
    }
    return seqs;
  }
};

InputLog read_input_log(const std::string& path) {
  InputLog log;
  lcm::LogFile file(path, "r");
  EXPECT_TRUE(file.good()) << path;
  const ChannelNames defaults;
  bool first = true;
  while (const lcm::LogEvent* e = file.readNextEvent()) {
    if (first) log.first_event_us = e->timestamp;
    first = false;
    if (e->channel == defaults.depth) {
      if (auto d = decode<depth_image_t>(*e)) log.frames.push_back(frame_of(*d, e->timestamp));
    } else if (e->channel == defaults.sim_joint_fault) {
      if (auto f = decode<sim_joint_fault_t>(*e)) log.fault_utime = f->utime;
    } else if (e->channel == defaults.sim_camera_fault) {
      if (auto f = decode<sim_camera_fault_t>(*e)) log.fault_utime = f->utime;
    }
  }
  return log;
}

// What the replay's lcm-logger recorded.
struct ReplayOutput {
  std::vector<Frame> frames;      // TOF_DEPTH as replayed
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

ReplayOutput read_output_log(const std::string& path, const deployment::Config& config) {
  ReplayOutput out;
  lcm::LogFile file(path, "r");
  EXPECT_TRUE(file.good()) << path;
  while (const lcm::LogEvent* e = file.readNextEvent()) {
    if (e->channel == config.channels.depth) {
      if (auto d = decode<depth_image_t>(*e)) out.frames.push_back(frame_of(*d, e->timestamp));
      if (out.first_input_us == 0) out.first_input_us = e->timestamp;
      out.last_input_us = e->timestamp;
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
  Replay(const std::string& log, const std::string& run_name)
      : config_(deployment::load_config(replay_config_path(), nullptr)), lcm_(config_.lcm.url) {
    output_log_ = output_dir() + "/" + run_name + ".lcmlog";
    std::filesystem::remove(output_log_);
    lcm_.subscribe(config_.channels.heartbeat, &Replay::on_heartbeat, this);
    lcm_.subscribe(config_.channels.risk, &Replay::on_risk, this);
    // The outputs, and the inputs as replayed (for the replay's timeline).
    logger_ = std::make_unique<Subprocess>(
        run_name + "-lcm-logger",
        std::vector<std::string>{in_path("lcm-logger"), "-q", "-f", "--flush-interval=20", "-c",
                                 "(SAFETY_.*|TOF_DEPTH|JOINT_STATE|CAMERA_POSE)",
                                 "--lcm-url=" + config_.lcm.url, output_log_});
    for (const std::string& name : kChain) {
      chain_.push_back(std::make_unique<Subprocess>(
          run_name + "-" + name,
          std::vector<std::string>{bin_dir() + "/" + name, "--config", replay_config_path()}));
    }
    // Ready: every process beats, and the logger writes (the heartbeats).
    const bool ready = wait_until(
        [&] {
          return heartbeats_.size() == kChain.size() && std::filesystem::exists(output_log_) &&
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
        [&] { return heartbeats_seen_ >= beats_at_last_verdict + 3 * static_cast<int>(kChain.size()); },
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
          std::vector<std::string>{bin_dir() + "/tofguard-reset", "--config", replay_config_path(), "--who",
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

std::string data_log(const std::string& name) {
  return std::string(TOFGUARD_REPLAY_DATA_DIR) + "/" + name + ".lcmlog";
}

// Every judged frame was replayed and got exactly one verdict (one failure
// each, naming the frames).
void expect_every_frame_judged_once(const InputLog& input, const ReplayOutput& out) {
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

// The verdicts on the judged frames, in seq order ("" for a frame without).
std::vector<const Verdict*> judged_verdicts(const InputLog& input, const ReplayOutput& out) {
  const auto by_seq = out.verdicts_by_seq();
  std::vector<const Verdict*> verdicts;
  for (int64_t seq : input.judged_seqs()) {
    const auto it = by_seq.find(seq);
    verdicts.push_back(it == by_seq.end() ? nullptr : it->second.front());
  }
  return verdicts;
}

// Both replays' (seq, level, cause, suspect) on every judged frame must be
// the same; the differences with their details otherwise.
void expect_same_verdicts(const InputLog& input, const ReplayOutput& first, const ReplayOutput& second) {
  const std::vector<const Verdict*> a = judged_verdicts(input, first);
  const std::vector<const Verdict*> b = judged_verdicts(input, second);
  int differences = 0;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    const std::string key_a = a[i] ? a[i]->key() : "(no verdict)";
    const std::string key_b = b[i] ? b[i]->key() : "(no verdict)";
    if (key_a == key_b) continue;
    ++differences;
    ADD_FAILURE() << "two replays judged a frame differently:\n  1st: " << key_a << " | "
                  << (a[i] ? a[i]->detail : "") << "\n  2nd: " << key_b << " | "
                  << (b[i] ? b[i]->detail : "");
  }
  EXPECT_EQ(a.size(), b.size());
  EXPECT_EQ(differences, 0);
}

std::string describe(const ReplayOutput& out) {
  std::string text;
  for (const Verdict& v : out.verdicts) text += "  " + v.key() + " | " + v.detail + "\n";
  if (const Status* stop = out.first_stop()) text += "  first stop: " + stop->reason + "\n";
  return text;
}

// Replays `name` twice; checks both runs with `check` and that they give the
// same verdict sequence.
void replay_twice(const std::string& name, const std::function<void(const InputLog&, const Replay&)>& check) {
  const std::string log = data_log(name);
  ASSERT_TRUE(std::filesystem::exists(log))
      << log << " missing (built from tests/data/" << name << ".lcmlog.xz)";
  ASSERT_FALSE(in_path("lcm-logplayer").empty() || in_path("lcm-logger").empty()) << "liblcm-bin missing";
  const InputLog input = read_input_log(log);
  ASSERT_GE(input.judged_seqs().size(), 10u) << log;
  std::vector<ReplayOutput> outputs;
  for (int run = 0; run < 2; ++run) {
    SCOPED_TRACE(name + " replay " + std::to_string(run + 1));
    const Replay replay(log, "replay-" + name + "-" + std::to_string(run + 1));
    const ReplayOutput& out = replay.output();
    expect_every_frame_judged_once(input, out);
    check(input, replay);
    outputs.push_back(out);
    if (::testing::Test::HasFailure()) {
      std::cout << "verdicts:\n" << describe(out) << replay.stderr_of_all() << std::flush;
    }
  }
  expect_same_verdicts(input, outputs[0], outputs[1]);
}

int64_t frame_period_us(const deployment::Config& config) {
  return static_cast<int64_t>(1e6 / config.camera.rate_hz);
}

// A fault log: motion allowed before the fault, then withdrawn with `cause`
// within `frames_to_dangerous` frame periods + the processing budget of the
// first affected frame's arrival; `suspect` (if not empty) blamed.
// The first affected frame: the first captured after the fault, or with
// `first_repeat` the first that repeats its predecessor's depth (a frozen
// camera repeats the last image captured before the fault).
void expect_fault_stop(const InputLog& input, const Replay& replay, int8_t cause, const std::string& suspect,
                       int frames_to_dangerous, bool first_repeat = false) {
  const ReplayOutput& out = replay.output();
  ASSERT_GT(input.fault_utime, 0) << "no fault marker in the log";
  const Frame* affected = nullptr;
  for (size_t i = 1; i < out.frames.size() && !affected; ++i) {
    if (first_repeat ? out.frames[i].depth_hash == out.frames[i - 1].depth_hash
                     : out.frames[i].utime >= input.fault_utime) {
      affected = &out.frames[i];
    }
  }
  ASSERT_NE(affected, nullptr) << "no frame captured after the fault";
  const int64_t allowed_us = out.first_allowed_us();
  ASSERT_TRUE(out.reset_accepted && allowed_us > 0) << "motion never allowed (no accepted reset)";
  ASSERT_LT(allowed_us, affected->received_us) << "motion allowed only after the fault";
  const Status* stop = out.first_stop();
  ASSERT_NE(stop, nullptr) << "no stop";
  ASSERT_GE(stop->received_us, affected->received_us) << "stopped before the fault: " << stop->reason;
  const int64_t latency_us = stop->received_us - affected->received_us;
  const int64_t budget_us = frames_to_dangerous * frame_period_us(replay.config()) + kProcessingBudgetUs;
  std::cout << "stop " << latency_us / 1000.0 << " ms after the first affected frame (seq " << affected->seq
            << "; budget " << budget_us / 1000 << " ms): " << stop->reason << std::endl;
  EXPECT_LE(latency_us, budget_us);
  EXPECT_EQ(risk_cause_name(stop->cause), risk_cause_name(cause)) << stop->reason;
  const Verdict* dangerous = out.first_dangerous_since(affected->received_us);
  ASSERT_NE(dangerous, nullptr);
  EXPECT_EQ(risk_cause_name(dangerous->cause), risk_cause_name(cause)) << dangerous->detail;
  if (!suspect.empty()) {
    EXPECT_EQ(dangerous->suspect, suspect) << dangerous->detail;
  }
}

TEST(Replay, NominalLogNeverStopsTheArm) {
  replay_twice("nominal", [](const InputLog& input, const Replay& replay) {
    const ReplayOutput& out = replay.output();
    const int64_t allowed_us = out.first_allowed_us();
    ASSERT_TRUE(out.reset_accepted && allowed_us > 0) << "motion never allowed (no accepted reset)";
    const Status* stop = out.first_stop();
    // The chain stops the arm when the log ends (every input goes stale):
    // only stops while the log still plays count.
    if (stop) {
      EXPECT_GT(stop->received_us, out.last_input_us) << "stopped during the log: " << stop->reason;
    }
    const std::set<int64_t> judged = input.judged_seqs();
    for (const Verdict& v : out.verdicts) {
      if (judged.count(v.seq)) {
        EXPECT_NE(v.level, risk_t::DANGEROUS) << v.key() << " | " << v.detail;
      }
    }
    for (const Verdict& v : out.timeouts) {
      if (v.received_us >= allowed_us && v.received_us <= out.last_input_us) {
        ADD_FAILURE() << "timeout while the log plays: " << v.key() << " | " << v.detail;
      }
    }
    std::cout << "nominal: motion allowed " << (allowed_us - out.first_input_us) / 1000
              << " ms into the replay, held for " << (out.last_input_us - allowed_us) / 1000
              << " ms until the log ended" << std::endl;
  });
}

TEST(Replay, EncoderOffsetStopsWithJointErrorOnA4) {
  replay_twice("encoder-offset", [](const InputLog& input, const Replay& replay) {
    expect_fault_stop(input, replay, risk_t::CAUSE_JOINT_ERROR, "a4",
                      replay.config().risk.debounce_frames - 1);
  });
}

TEST(Replay, CameraPoseOffsetStopsWithCalibrationError) {
  replay_twice("camera-pose", [](const InputLog& input, const Replay& replay) {
    expect_fault_stop(input, replay, risk_t::CAUSE_CALIBRATION_ERROR, "",
                      replay.config().risk.debounce_frames - 1);
  });
}

TEST(Replay, IntrudingObjectStopsWithUnknownObject) {
  replay_twice("intruding-object", [](const InputLog& input, const Replay& replay) {
    expect_fault_stop(input, replay, risk_t::CAUSE_UNKNOWN_OBJECT, "",
                      replay.config().risk.debounce_frames - 1);
  });
}

TEST(Replay, FrozenImageStopsWithSensorFault) {
  replay_twice("frozen-image", [](const InputLog& input, const Replay& replay) {
    // The first repeat has repeat_count 1: frozen_repeat_frames - 1 more
    // frames start the finding, then the sensor debounce.
    const risk::RiskSettings& risk = replay.config().risk;
    expect_fault_stop(input, replay, risk_t::CAUSE_SENSOR_FAULT, "TOF_DEPTH",
                      risk.frozen_repeat_frames - 1 + risk.sensor_debounce_frames - 1, /*first_repeat=*/true);
  });
}

TEST(Replay, CameraStallStopsWithSensorFaultWithinTheDepthDeadline) {
  replay_twice("camera-stall", [](const InputLog& input, const Replay& replay) {
    const ReplayOutput& out = replay.output();
    ASSERT_GT(input.fault_utime, 0);
    ASSERT_FALSE(out.frames.empty());
    const Frame& last_frame = out.frames.back();
    ASSERT_LT(last_frame.utime, input.fault_utime) << "frames after the stall";
    ASSERT_TRUE(out.reset_accepted && out.first_allowed_us() > 0) << "motion never allowed";
    ASSERT_LT(out.first_allowed_us(), last_frame.received_us);
    const Status* stop = out.first_stop();
    ASSERT_NE(stop, nullptr) << "no stop";
    ASSERT_GE(stop->received_us, last_frame.received_us) << "stopped before the stall: " << stop->reason;
    // The joint states play on: the stop is the stall's, not the log's end.
    EXPECT_LT(stop->received_us, out.last_input_us);
    const int64_t latency_us = stop->received_us - last_frame.received_us;
    const int64_t budget_us = replay.config().risk.depth_deadline_us + kProcessingBudgetUs;
    std::cout << "camera stall: stop " << latency_us / 1000.0 << " ms after the last frame (budget "
              << budget_us / 1000 << " ms): " << stop->reason << std::endl;
    EXPECT_LE(latency_us, budget_us);
    EXPECT_EQ(risk_cause_name(stop->cause), risk_cause_name(risk_t::CAUSE_SENSOR_FAULT)) << stop->reason;
    const Verdict* dangerous = out.first_dangerous_since(last_frame.received_us);
    ASSERT_NE(dangerous, nullptr);
    EXPECT_EQ(dangerous->suspect, "TOF_DEPTH") << dangerous->detail;
  });
}

}  // namespace
}  // namespace tofguard::test
