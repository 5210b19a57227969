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

#include "log_replay.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/sim_camera_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

// How long processing may add to the frames a fault needs before it is
// DANGEROUS (the e2e test's budget: 200 ms at 30 Hz for two frame periods,
// 133 ms of it processing; more here for a loaded 2-core machine).
constexpr int64_t kProcessingBudgetUs = 200'000;

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
    // The recordings in tests/data show the wheelchair empty: the chain
    // that replays them models no user (with the default's user it would
    // rightly stop: the user is not where the model seats them).
    std::string text = read_file(p);
    erase_config_section(&text, "occupant");
    write_file(p, text);
    return p;
  }();
  return path;
}

// The same for the two-camera scene (config/sim-two-cameras.yaml), whose
// recordings show the user seated: its occupant stays.
const std::string& two_camera_replay_config_path() {
  static const std::string path = [] {
    const std::string p = output_dir() + "/replay-two-cameras.yaml";
    std::string out, err;
    const int code = run_command("replay-write-two-camera-config",
                                 {"/bin/bash", source_dir() + "/scripts/record-scenario", "--write-config", p,
                                  "--replay", "--config", source_dir() + "/config/sim-two-cameras.yaml"},
                                 &out, &err);
    if (code != 0) throw std::runtime_error("record-scenario --write-config failed: " + out + err);
    return p;
  }();
  return path;
}

std::string data_log(const std::string& name) {
  return std::string(TOFGUARD_REPLAY_DATA_DIR) + "/" + name + ".lcmlog";
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

// With several cameras the published verdict is the worst of every
// camera's latest (VerdictFusion), so which frame's seq it carries, and
// whether a frame captured as a fault begins is answered before or after
// the other camera's, follows the cameras' arrival order (so does the
// start, before each camera has a frame judged). What must be the same on
// both replays once motion is allowed: the first DANGEROUS frame verdict's
// cause, suspect and camera (its seq within one frame), and the verdicts'
// counts by (level, cause, suspect) within one per camera.
void expect_same_verdicts_of_every_camera(const InputLog& input, const ReplayOutput& first,
                                          const ReplayOutput& second) {
  auto first_dangerous = [](const ReplayOutput& out) -> const Verdict* {
    for (const Verdict& v : out.verdicts) {
      if (v.level == risk_t::DANGEROUS && v.received_us > out.first_allowed_us()) return &v;
    }
    return nullptr;
  };
  auto what = [](const Verdict& v) {
    return risk_cause_name(v.cause) + " '" + v.suspect + "' " + v.detail.substr(0, v.detail.find(": "));
  };
  const Verdict* a = first_dangerous(first);
  const Verdict* b = first_dangerous(second);
  ASSERT_EQ(a == nullptr, b == nullptr) << "one replay judged a frame DANGEROUS, the other none";
  if (a) {
    EXPECT_EQ(what(*a), what(*b)) << a->detail << "\n" << b->detail;
    EXPECT_LE(std::abs(a->seq - b->seq), 1) << a->key() << " | " << b->key();
  }
  auto counts = [](const ReplayOutput& out) {
    std::map<std::string, int> n;
    for (const Verdict& v : out.verdicts) {
      if (v.received_us <= out.first_allowed_us()) continue;
      ++n[risk_level_name(v.level) + " " + risk_cause_name(v.cause) + " '" + v.suspect + "'"];
    }
    return n;
  };
  std::map<std::string, int> in_first = counts(first), in_second = counts(second);
  const int cameras = static_cast<int>(input.frames_of_camera.size());
  for (const auto* m : {&in_first, &in_second}) {
    for (const auto& [key, n] : *m) {
      EXPECT_LE(std::abs(in_first[key] - in_second[key]), cameras)
          << key << ": " << in_first[key] << " verdicts in the 1st replay, " << in_second[key]
          << " in the 2nd";
    }
  }
}

// Replays `name` twice on `config_path`; checks both runs with `check` and
// that they give the same verdict sequence.
void replay_twice(const std::string& name, const std::function<void(const InputLog&, const Replay&)>& check,
                  const std::string& config_path = replay_config_path()) {
  const std::string log = data_log(name);
  ASSERT_TRUE(std::filesystem::exists(log))
      << log << " missing (built from tests/data/" << name << ".lcmlog.xz)";
  ASSERT_FALSE(in_path("lcm-logplayer").empty() || in_path("lcm-logger").empty()) << "liblcm-bin missing";
  const InputLog input = read_input_log(log);
  ASSERT_GE(input.judged_seqs().size(), 10u) << log;
  std::vector<ReplayOutput> outputs;
  for (int run = 0; run < 2; ++run) {
    SCOPED_TRACE(name + " replay " + std::to_string(run + 1));
    const Replay replay(log, "replay-" + name + "-" + std::to_string(run + 1), config_path);
    const ReplayOutput& out = replay.output();
    if (replay.config().cameras.size() > 1) {
      expect_every_camera_frame_judged_once(input, out);
    } else {
      expect_every_frame_judged_once(input, out);
    }
    check(input, replay);
    outputs.push_back(out);
    if (::testing::Test::HasFailure()) {
      std::cout << "verdicts:\n" << describe(out) << replay.stderr_of_all() << std::flush;
    }
  }
  if (input.frames_of_camera.size() > 1) {
    expect_same_verdicts_of_every_camera(input, outputs[0], outputs[1]);
  } else {
    expect_same_verdicts(input, outputs[0], outputs[1]);
  }
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
// With several cameras `camera_id` names the camera the fault is in (its
// frames are the affected ones), and the stop must name it.
void expect_fault_stop(const InputLog& input, const Replay& replay, int8_t cause, const std::string& suspect,
                       int frames_to_dangerous, bool first_repeat = false,
                       const std::string& camera_id = "") {
  const ReplayOutput& out = replay.output();
  ASSERT_GT(input.fault_utime, 0) << "no fault marker in the log";
  ASSERT_TRUE(camera_id.empty() || out.frames_of_camera.count(camera_id)) << "no frames of " << camera_id;
  const std::vector<Frame>& frames = camera_id.empty() ? out.frames : out.frames_of_camera.at(camera_id);
  const Frame* affected = nullptr;
  for (size_t i = 1; i < frames.size() && !affected; ++i) {
    if (first_repeat ? frames[i].depth_hash == frames[i - 1].depth_hash
                     : frames[i].utime >= input.fault_utime) {
      affected = &frames[i];
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
  if (!camera_id.empty()) {
    EXPECT_EQ(dangerous->detail.rfind(camera_id + ": ", 0), 0u) << "not named: " << dangerous->detail;
    EXPECT_NE(stop->reason.find(camera_id + ": "), std::string::npos) << stop->reason;
  }
}

// A nominal log: motion allowed after the start-up reset and never
// withdrawn, and no timeout verdict, while the log plays (the chain stops
// the arm when the log ends: every input goes stale). Returns when motion
// was allowed (-1: never, a failure).
int64_t expect_motion_held_while_the_log_plays(const ReplayOutput& out) {
  const int64_t allowed_us = out.first_allowed_us();
  EXPECT_TRUE(out.reset_accepted && allowed_us > 0) << "motion never allowed (no accepted reset)";
  if (!out.reset_accepted || allowed_us <= 0) return -1;
  if (const Status* stop = out.first_stop()) {
    EXPECT_GT(stop->received_us, out.last_input_us) << "stopped during the log: " << stop->reason;
  }
  for (const Verdict& v : out.timeouts) {
    if (v.received_us >= allowed_us && v.received_us <= out.last_input_us) {
      ADD_FAILURE() << "timeout while the log plays: " << v.key() << " | " << v.detail;
    }
  }
  return allowed_us;
}

TEST(Replay, NominalLogNeverStopsTheArm) {
  replay_twice("nominal", [](const InputLog& input, const Replay& replay) {
    const ReplayOutput& out = replay.output();
    const int64_t allowed_us = expect_motion_held_while_the_log_plays(out);
    if (allowed_us < 0) return;
    const std::set<int64_t> judged = input.judged_seqs();
    for (const Verdict& v : out.verdicts) {
      if (judged.count(v.seq)) {
        EXPECT_NE(v.level, risk_t::DANGEROUS) << v.key() << " | " << v.detail;
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

// The two-camera scene (config/sim-two-cameras.yaml, the user seated):
// each camera's frames judged once, and the arm allowed to move until the
// log ends.
TEST(Replay, TwoCamerasNominalLogNeverStopsTheArm) {
  replay_twice(
      "two-cameras-nominal",
      [](const InputLog& input, const Replay& replay) {
        const ReplayOutput& out = replay.output();
        const int64_t allowed_us = expect_motion_held_while_the_log_plays(out);
        if (allowed_us < 0) return;
        for (const Verdict& v : out.verdicts) {
          if (v.received_us >= allowed_us && v.received_us <= out.last_input_us) {
            EXPECT_NE(v.level, risk_t::DANGEROUS) << v.key() << " | " << v.detail;
          }
        }
        for (const auto& [camera_id, seqs] : out.discrepancy_seqs_of_camera) {
          std::cout << camera_id << ": " << seqs.size() << " frames judged of "
                    << input.frames_of_camera.at(camera_id).size() << " in the log" << std::endl;
        }
      },
      two_camera_replay_config_path());
}

// The side camera knocked 5 cm along its pose frame's x: a calibration
// error, named by that camera's id, within the stop budget of its first
// frame after the knock.
TEST(Replay, TwoCamerasSideCameraKnockedStopsNamingIt) {
  replay_twice(
      "two-cameras-side-camera-pose",
      [](const InputLog& input, const Replay& replay) {
        expect_fault_stop(input, replay, risk_t::CAUSE_CALIBRATION_ERROR, "",
                          replay.config().risk.debounce_frames - 1, false, "tof-side");
      },
      two_camera_replay_config_path());
}

}  // namespace
}  // namespace tofguard::test
