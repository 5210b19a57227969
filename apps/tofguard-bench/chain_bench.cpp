#include "chain_bench.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <unordered_map>

#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "joint_motion.hpp"
#include "plot_panel.hpp"
#include "proc_stats.hpp"
#include "report_format.hpp"
#include "scaled_intrinsics.hpp"
#include "simulated_frames.hpp"
#include "tofguard/authenticated_message_t.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/renderer/renderer_service.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/robot_model/arm_spheres.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

namespace fs = std::filesystem;

// The observer chain, the judge first so that it listens before its inputs
// speak (as LiveChain starts it).
const std::vector<std::string> kChainProcesses = {"tofguard-intervene", "tofguard-risk",
                                                  "tofguard-discrepancy", "tofguard-renderer"};
const std::string kBenchProcess = "tofguard-bench";

// At most this many distinct frames are prepared per step; longer steps play
// them forwards and backwards (the arm reverses), so memory stays bounded at
// 640x480 and high rates while every frame differs from the one before.
constexpr int kMaxPreparedFrames = 150;
// Joint states between frames at this period at least (the arm driver's
// 100 Hz of config/sim.yaml), besides one at each frame's utime.
constexpr int64_t kJointStatePeriodUs = 10000;
// With BenchOptions::plan: a chunk of the plan every kPlanChunkFrames frames,
// reaching 2 * kPlanChunkFrames frames ahead (a few kB on the safety URL,
// whatever the step's length; each chunk replaces the plan from its first
// point on).
constexpr int64_t kPlanChunkFrames = 30;
// Frames in a row that must come through before the measured step starts.
constexpr int kWarmupFrames = 5;
// Before each step's measured frames, this many at the step's rate, not
// measured: the chain then runs as it does behind a camera at that rate.
// The warm-up sends one frame at a time, each after the last verdict, and
// the ramp changes the rate from step to step; tofguard-renderer learns the
// camera's period from its last 9 frame intervals and predicts only after 5
// misses in a row every 8th frame (renderer_process.cpp), so without a
// lead-in a step's first 8-10 frames had no prediction and were rendered on
// their critical path: 3 of the 12 slowest frames of a 300-frame step
// (--frames, 2026-11-27). The measured frames start after the lead-in's
// verdicts and the renderer's next heartbeat, so their first frame comes
// later than one period; its prediction is still the lead-in plan's last
// point (one past the lead-in), at the same joints, and a hit (299-300 hits
// of 300 in the runs of 2026-11-27).
constexpr int64_t kLeadInFrames = 20;
// The chain's start (EGL, mesh loading, the arm's cover of spheres) may
// take this long on a loaded 2-core machine with the iiwa14's meshes.
constexpr auto kStartDeadline = std::chrono::seconds(90);

std::string number_text(double value) {
  std::ostringstream s;
  s << std::setprecision(12) << value;
  return s.str();
}

std::string size_text(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

LatencySummary summarise(std::vector<double> latency_ms) {
  LatencySummary s;
  s.count = static_cast<int>(latency_ms.size());
  if (latency_ms.empty()) return s;
  std::sort(latency_ms.begin(), latency_ms.end());
  s.p50_ms = quantile(latency_ms, 0.5);
  s.p99_ms = quantile(latency_ms, 0.99);
  s.max_ms = latency_ms.back();
  return s;
}

// LCM's encoding is big-endian.
void put_int64_be(uint8_t* at, int64_t value) {
  for (int i = 7; i >= 0; --i) {
    at[i] = static_cast<uint8_t>(value & 0xff);
    value >>= 8;
  }
}
int64_t get_int64_be(const uint8_t* at) {
  uint64_t value = 0;
  for (int i = 0; i < 8; ++i) value = (value << 8) | at[i];
  return static_cast<int64_t>(value);
}

// depth_image_t, discrepancy_t and risk_t all begin with the type's hash,
// then utime and seq (lcmtypes/). The bench reads only those, so that it
// does not spend the 2 cores decoding 640x480 images the chain needs.
constexpr size_t kHashUtimeSeqBytes = 24;
constexpr size_t kSeqOffset = 16;
constexpr size_t kUtimeOffset = 8;
// With several cameras camera c's k-th frame carries seq
// c * kCameraSeqStride + k: each stage's message (TOF_RENDERED,
// SAFETY_DISCREPANCY, the verdict on SAFETY_RISK) then says whose frame it
// is by its seq alone. Camera 0's seqs are those of one camera.
constexpr int64_t kCameraSeqStride = 1'000'000'000;

// When each stage's message of a frame arrived (monotonic us, 0: not yet).
struct FrameArrivals {
  int64_t sent_us = 0;
  int64_t rendered_us = 0;
  int64_t discrepancy_us = 0;
  int64_t risk_us = 0;
  int8_t level = -1;         // the verdict's risk_t level
  bool risk_signed = false;  // its first copy was the signed one
  // SAFETY_DISCREPANCY's compute_us: tofguard-discrepancy's own time for
  // compute_discrepancy on the frame (-1: none came or it did not decode).
  int32_t compute_us = -1;
};

// Polls an LCM instance on each of the chain's two URLs from a thread of
// its own until destroyed.
class TwoUrlThread {
 public:
  TwoUrlThread(const std::string& safety_url, const std::string& image_url)
      : safety_(safety_url), images_(image_url) {
    if (!safety_.good() || !images_.good())
      throw std::runtime_error("cannot open LCM (" + safety_url + ", " + image_url + ")");
    // LCM 1.3 joins the multicast groups lazily (first getFileno()/handle()):
    // join now, so nothing published once this is constructed is missed.
    safety_.getFileno();
    images_.getFileno();
  }
  ~TwoUrlThread() { stop(); }
  TwoUrlThread(const TwoUrlThread&) = delete;
  TwoUrlThread& operator=(const TwoUrlThread&) = delete;

  lcm::LCM& safety() { return safety_; }
  lcm::LCM& images() { return images_; }
  // After the subscriptions.
  void start() {
    thread_ = std::thread([this] {
      pollfd fds[2] = {{safety_.getFileno(), POLLIN, 0}, {images_.getFileno(), POLLIN, 0}};
      while (!stop_) {
        if (poll(fds, 2, 20) <= 0) continue;
        if (fds[0].revents & POLLIN) safety_.handleTimeout(0);
        if (fds[1].revents & POLLIN) images_.handleTimeout(0);
      }
    });
  }
  // Before the members a handler uses go.
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  lcm::LCM safety_;
  lcm::LCM images_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// Receives TOF_RENDERED, SAFETY_DISCREPANCY and SAFETY_RISK on its own
// thread and LCM sockets, so that the publisher's pacing does not delay the
// time stamps; records the first arrival of each per frame seq. A verdict
// is taken from whichever copy comes first: with a key, tofguard-risk
// publishes each signed on SAFETY_RISK_AUTH first (the copy
// tofguard-intervene acts on), then plain on SAFETY_RISK
// (auth::publish_signed).
class ArrivalRecorder {
 public:
  // `cameras`: each camera's channels (TOF_RENDERED and
  // SAFETY_DISCREPANCY of its own); the verdicts are on config's.
  ArrivalRecorder(const deployment::Config& config, const std::vector<ChannelNames>& cameras)
      : risk_channel_(config.channels.risk), lcm_(config.lcm.url, config.lcm.image_url) {
    for (const ChannelNames& camera : cameras) {
      lcm_.images().subscribe(camera.rendered, &ArrivalRecorder::on_rendered, this);
      lcm_.safety().subscribe(camera.discrepancy, &ArrivalRecorder::on_discrepancy, this);
    }
    lcm_.safety().subscribe(config.channels.risk, &ArrivalRecorder::on_risk, this);
    lcm_.safety().subscribe(config.channels.risk_auth, &ArrivalRecorder::on_signed_risk, this);
    lcm_.safety().subscribe(config.channels.heartbeat, &ArrivalRecorder::on_heartbeat, this);
    lcm_.start();
  }
  ~ArrivalRecorder() { lcm_.stop(); }
  ArrivalRecorder(const ArrivalRecorder&) = delete;
  ArrivalRecorder& operator=(const ArrivalRecorder&) = delete;

  void sent(int64_t seq, int64_t at_us) {
    std::lock_guard<std::mutex> lock(mutex_);
    frames_[seq].sent_us = at_us;
  }
  FrameArrivals arrivals(int64_t seq) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = frames_.find(seq);
    return it == frames_.end() ? FrameArrivals{} : it->second;
  }
  // Waits until every frame of [first_seq, last_seq] has its SAFETY_RISK,
  // or until `deadline_us` (monotonic). Returns whether all came.
  bool wait_for_verdicts(int64_t first_seq, int64_t last_seq, int64_t deadline_us) {
    std::unique_lock<std::mutex> lock(mutex_);
    // The frames before `unjudged` have their verdicts: each wake-up scans
    // on from there.
    int64_t unjudged = first_seq;
    const auto all_judged = [&] {
      for (; unjudged <= last_seq; ++unjudged) {
        const auto it = frames_.find(unjudged);
        if (it == frames_.end() || it->second.risk_us == 0) return false;
      }
      return true;
    };
    while (!all_judged()) {
      const int64_t left_us = deadline_us - monotonic_us();
      if (left_us <= 0) return false;
      verdict_.wait_for(lock, std::chrono::microseconds(std::min<int64_t>(left_us, 20000)));
    }
    return true;
  }
  // Waits until one frame of `seqs` has its SAFETY_RISK, or until
  // `deadline_us` (monotonic). Returns whether one came.
  bool wait_for_any_verdict(const std::vector<int64_t>& seqs, int64_t deadline_us) {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto one_judged = [&] {
      return std::any_of(seqs.begin(), seqs.end(), [&](int64_t seq) {
        const auto it = frames_.find(seq);
        return it != frames_.end() && it->second.risk_us != 0;
      });
    };
    while (!one_judged()) {
      const int64_t left_us = deadline_us - monotonic_us();
      if (left_us <= 0) return false;
      verdict_.wait_for(lock, std::chrono::microseconds(std::min<int64_t>(left_us, 20000)));
    }
    return true;
  }
  // Forgets every camera's frames before its `seq`-th.
  void forget_before(int64_t seq) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = frames_.begin(); it != frames_.end();)
      it = it->first % kCameraSeqStride < seq ? frames_.erase(it) : ++it;
  }
  // tofguard-renderer's prediction counts as of the frame captured at
  // `frame_utime`: from its newest heartbeat once one says it has handled
  // that frame or a later one (heartbeat_t.last_frame_utime; the process
  // sets it and the counts together, after each frame), waiting for one
  // until `deadline_us` (monotonic); nullopt when none came or its status
  // did not say. (Taken by arrival time instead, a heartbeat sent just
  // before the frame's render and received after it, on a loaded machine,
  // left that frame out of its step: 29 of 30 under ASan.)
  std::optional<renderer::RendererService::PredictionStats> renderer_prediction(int64_t frame_utime,
                                                                                int64_t deadline_us) {
    std::unique_lock<std::mutex> lock(mutex_);
    while (renderer_last_frame_utime_ < frame_utime) {
      const int64_t left_us = deadline_us - monotonic_us();
      if (left_us <= 0) return std::nullopt;
      heartbeat_.wait_for(lock, std::chrono::microseconds(std::min<int64_t>(left_us, 20000)));
    }
    return renderer::RendererService::prediction_stats_from_status(renderer_status_);
  }
  // The largest TOF_RENDERED, SAFETY_DISCREPANCY and SAFETY_RISK received
  // for the bench's frames, bytes (0: none came).
  enum class Stage { kRendered, kDiscrepancy, kRisk };
  size_t largest_message(Stage stage) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return largest_[static_cast<int>(stage)];
  }

 private:
  void record(const lcm::ReceiveBuffer* buffer, int64_t hash, Stage stage) {
    record(static_cast<const uint8_t*>(buffer->data), buffer->data_size, monotonic_us(), hash, stage, false);
  }
  // The message `bytes` (LCM-encoded, `size` bytes) arrived at `now_us`;
  // `is_signed`: it came as the payload of its signed copy.
  void record(const uint8_t* bytes, size_t size, int64_t now_us, int64_t hash, Stage stage, bool is_signed) {
    if (size < kHashUtimeSeqBytes) return;
    if (get_int64_be(bytes) != hash) return;
    const int64_t seq = get_int64_be(bytes + kSeqOffset);
    if (seq < 0) return;  // a timeout verdict, about no frame
    // SAFETY_DISCREPANCY (3 kB) is decoded whole for its compute_us (the
    // images never are), before the lock: the publisher takes it to stamp
    // each frame it sends.
    int32_t compute_us = -1;
    if (stage == Stage::kDiscrepancy) {
      discrepancy_t summary;
      if (summary.decode(bytes, 0, static_cast<int>(size)) >= 0) compute_us = summary.compute_us;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = frames_.find(seq);
    if (it == frames_.end()) return;  // not a frame this bench sent (or forgotten)
    size_t& largest = largest_[static_cast<int>(stage)];
    largest = std::max(largest, size);
    int64_t& at = stage == Stage::kRendered      ? it->second.rendered_us
                  : stage == Stage::kDiscrepancy ? it->second.discrepancy_us
                                                 : it->second.risk_us;
    if (at != 0) return;
    at = now_us;
    if (stage == Stage::kDiscrepancy) it->second.compute_us = compute_us;
    if (stage != Stage::kRisk) return;
    it->second.risk_signed = is_signed;
    // risk_t's level follows its seq.
    if (size > kHashUtimeSeqBytes) it->second.level = static_cast<int8_t>(bytes[kHashUtimeSeqBytes]);
    verdict_.notify_all();
  }
  void on_rendered(const lcm::ReceiveBuffer* b, const std::string&) {
    record(b, depth_image_t::getHash(), Stage::kRendered);
  }
  void on_discrepancy(const lcm::ReceiveBuffer* b, const std::string&) {
    record(b, discrepancy_t::getHash(), Stage::kDiscrepancy);
  }
  void on_risk(const lcm::ReceiveBuffer* b, const std::string&) {
    record(b, risk_t::getHash(), Stage::kRisk);
  }
  // The signed copy: its payload is the risk_t as SAFETY_RISK carries it
  // (the tag is tofguard-intervene's to check, not the bench's).
  void on_signed_risk(const lcm::ReceiveBuffer* b, const std::string&) {
    const int64_t now_us = monotonic_us();
    authenticated_message_t signed_message;
    if (signed_message.decode(b->data, 0, static_cast<int>(b->data_size)) < 0 ||
        signed_message.channel != risk_channel_)
      return;
    record(signed_message.payload.data(), signed_message.payload.size(), now_us, risk_t::getHash(),
           Stage::kRisk, true);
  }
  void on_heartbeat(const lcm::ReceiveBuffer* b, const std::string&) {
    heartbeat_t h;
    if (h.decode(b->data, 0, static_cast<int>(b->data_size)) < 0 || h.process != "tofguard-renderer") return;
    std::lock_guard<std::mutex> lock(mutex_);
    renderer_status_ = h.status;
    renderer_last_frame_utime_ = h.last_frame_utime;
    heartbeat_.notify_all();
  }

  const std::string risk_channel_;
  mutable std::mutex mutex_;
  std::condition_variable verdict_;
  std::condition_variable heartbeat_;
  std::string renderer_status_;
  int64_t renderer_last_frame_utime_ = 0;  // of the newest renderer heartbeat
  std::unordered_map<int64_t, FrameArrivals> frames_;
  size_t largest_[3] = {0, 0, 0};
  TwoUrlThread lcm_;  // last: its thread stops before the members go
};

// The LCM hop floor's receiver: its own thread and LCM instances on the
// chain's two URLs, subscribed to the scratch channels; each message
// carries its kind, the monotonic time it was published at and a sequence
// number. Kinds 0-2: the hops (kHopChannels); 3 + r and 5 + r: relay r's
// message in and out (kRelayInChannels, kRelayOutChannels; r = 0 the
// discrepancy relay, 1 the risk relay), received here both, the relay's
// latency the out's receive time minus the in's.
const std::string kHopChannels[3] = {"TOFGUARD_BENCH_HOP_IMAGE", "TOFGUARD_BENCH_HOP_DISCREPANCY",
                                     "TOFGUARD_BENCH_HOP_RISK"};
const std::string kRelayInChannels[2] = {"TOFGUARD_BENCH_RELAY_IMAGE_IN",
                                         "TOFGUARD_BENCH_RELAY_DISCREPANCY_IN"};
const std::string kRelayOutChannels[2] = {"TOFGUARD_BENCH_RELAY_DISCREPANCY_OUT",
                                          "TOFGUARD_BENCH_RELAY_RISK_OUT"};
constexpr size_t kHopHeaderBytes = 24;  // kind, sent_us, seq (big-endian int64 each)
constexpr int64_t kRelayInKind = 3;
constexpr int64_t kRelayOutKind = 5;

class HopReceiver {
 public:
  HopReceiver(const std::string& safety_url, const std::string& image_url) : lcm_(safety_url, image_url) {
    lcm_.images().subscribe(kHopChannels[0], &HopReceiver::on_message, this);
    lcm_.safety().subscribe(kHopChannels[1], &HopReceiver::on_message, this);
    lcm_.safety().subscribe(kHopChannels[2], &HopReceiver::on_message, this);
    lcm_.images().subscribe(kRelayInChannels[0], &HopReceiver::on_message, this);
    lcm_.safety().subscribe(kRelayInChannels[1], &HopReceiver::on_message, this);
    for (const std::string& channel : kRelayOutChannels)
      lcm_.safety().subscribe(channel, &HopReceiver::on_message, this);
    lcm_.start();
  }
  ~HopReceiver() { lcm_.stop(); }
  HopReceiver(const HopReceiver&) = delete;
  HopReceiver& operator=(const HopReceiver&) = delete;

  size_t received() const {
    std::lock_guard<std::mutex> lock(mutex_);
    size_t n = latency_ms_[0].size() + latency_ms_[1].size() + latency_ms_[2].size();
    for (int r = 0; r < 2; ++r) n += relay_in_us_[r].size() + relay_out_us_[r].size();
    return n;
  }
  std::vector<double> latency_ms(int kind) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return latency_ms_[kind];
  }
  // Relay r's latencies: for each sequence number received both in and out,
  // the out's receive time minus the in's (below 0 when this thread read
  // the out first: the two may come on different sockets).
  std::vector<double> relay_latency_ms(int r) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<double> ms;
    for (const auto& [seq, out_us] : relay_out_us_[r]) {
      const auto in = relay_in_us_[r].find(seq);
      if (in != relay_in_us_[r].end()) ms.push_back((out_us - in->second) * 1e-3);
    }
    return ms;
  }

 private:
  void on_message(const lcm::ReceiveBuffer* buffer, const std::string&) {
    const int64_t now_us = monotonic_us();
    if (buffer->data_size < kHopHeaderBytes) return;
    const auto* bytes = static_cast<const uint8_t*>(buffer->data);
    const int64_t kind = get_int64_be(bytes);
    std::lock_guard<std::mutex> lock(mutex_);
    if (kind >= 0 && kind <= 2) {
      latency_ms_[kind].push_back((now_us - get_int64_be(bytes + 8)) * 1e-3);
    } else if (kind == kRelayInKind || kind == kRelayInKind + 1) {
      relay_in_us_[kind - kRelayInKind][get_int64_be(bytes + 16)] = now_us;
    } else if (kind == kRelayOutKind || kind == kRelayOutKind + 1) {
      relay_out_us_[kind - kRelayOutKind][get_int64_be(bytes + 16)] = now_us;
    }
  }

  mutable std::mutex mutex_;
  std::vector<double> latency_ms_[3];
  std::map<int64_t, int64_t> relay_in_us_[2];
  std::map<int64_t, int64_t> relay_out_us_[2];
  TwoUrlThread lcm_;  // last: its thread stops before the members go
};

// An LCM instance on each URL that reads everything sent there and handles
// nothing (subscribed to a channel nobody publishes), as a chain process
// does with the channels it does not read (BenchOptions::floor_listeners).
class IdleListener {
 public:
  IdleListener(const std::string& safety_url, const std::string& image_url) : lcm_(safety_url, image_url) {
    lcm_.safety().subscribe(kIdleChannel, &IdleListener::on_message, this);
    lcm_.images().subscribe(kIdleChannel, &IdleListener::on_message, this);
    lcm_.start();
  }
  ~IdleListener() { lcm_.stop(); }
  IdleListener(const IdleListener&) = delete;
  IdleListener& operator=(const IdleListener&) = delete;

 private:
  static constexpr const char* kIdleChannel = "TOFGUARD_BENCH_FLOOR_IDLE";
  void on_message(const lcm::ReceiveBuffer*, const std::string&) {}
  TwoUrlThread lcm_;
};

// The relays' middle (BenchFloors::discrepancy_relay, risk_relay): its own
// thread and LCM instances; on each relay r's message in it publishes, at
// once, relay r's message out (out_bytes[r] bytes, the same sequence
// number) on lcm.url, as a chain process publishes its result.
class HopRelay {
 public:
  HopRelay(const std::string& safety_url, const std::string& image_url, const size_t out_bytes[2])
      : lcm_(safety_url, image_url) {
    for (int r = 0; r < 2; ++r) {
      out_[r].assign(std::max(out_bytes[r], kHopHeaderBytes), 0);
      put_int64_be(out_[r].data(), kRelayOutKind + r);
    }
    lcm_.images().subscribe(kRelayInChannels[0], &HopRelay::on_message, this);
    lcm_.safety().subscribe(kRelayInChannels[1], &HopRelay::on_message, this);
    lcm_.start();
  }
  ~HopRelay() { lcm_.stop(); }
  HopRelay(const HopRelay&) = delete;
  HopRelay& operator=(const HopRelay&) = delete;

 private:
  void on_message(const lcm::ReceiveBuffer* buffer, const std::string&) {
    if (buffer->data_size < kHopHeaderBytes) return;
    const auto* bytes = static_cast<const uint8_t*>(buffer->data);
    const int64_t r = get_int64_be(bytes) - kRelayInKind;
    if (r < 0 || r > 1) return;
    std::vector<uint8_t>& out = out_[r];
    put_int64_be(out.data() + 8, monotonic_us());
    put_int64_be(out.data() + 16, get_int64_be(bytes + 16));
    lcm_.safety().publish(kRelayOutChannels[r], out.data(), static_cast<unsigned int>(out.size()));
  }

  std::vector<uint8_t> out_[2];
  TwoUrlThread lcm_;  // last: its thread stops before the members go
};

// The arm's path for a step: `prepared` frames taken 1/rate apart in motion
// time, played forwards then backwards. Real time t maps to motion time
// path_s(t), a triangle wave, so frame k (at t = k / rate) shows the pose
// of prepared frame index(k), and a joint state at any t lies on the same
// smooth path (continuous position; the velocity reverses at the ends).
struct ArmPath {
  double rate_hz = 30;
  int prepared = 1;
  double start_s = 0;  // motion time of prepared frame 0

  double span_s() const { return (prepared - 1) / rate_hz; }
  int index(int64_t k) const {
    if (prepared <= 1) return 0;
    const int64_t cycle = 2 * (prepared - 1);
    const int64_t i = k % cycle;
    return static_cast<int>(i < prepared ? i : cycle - i);
  }
  // Motion time at real time t_s after the step's start, and its direction.
  std::pair<double, double> at(double t_s) const {
    if (prepared <= 1) return {start_s, 0.0};
    const double period_s = 2 * span_s();
    const double phase_s = std::fmod(t_s, period_s);
    return phase_s <= span_s() ? std::make_pair(start_s + phase_s, 1.0)
                               : std::make_pair(start_s + period_s - phase_s, -1.0);
  }
};

// One camera of the bench's deployment: the deployment as its processes
// see it, the frames it sends (prepared per step), and the seqs they carry.
struct BenchCamera {
  deployment::Config config;  // deployment::select_camera's with several cameras
  std::unique_ptr<SimulatedFrames> frames;
  std::vector<std::vector<uint8_t>> encoded;
  // Exposing after camera 0 (BenchOptions::camera_offset_ms): each frame
  // made with the arm as far back along the path (played backwards); empty
  // otherwise.
  std::vector<std::vector<uint8_t>> encoded_behind;
  int64_t seq_base = 0;  // c * kCameraSeqStride for camera c
};

// One arm at one camera size: its config, the chain running on it, the
// bench's publisher and receiver, and the simulated cameras that prepare
// the frames.
class BenchChain {
 public:
  BenchChain(const std::string& arm_name, const CampaignArm& arm, const Intrinsics& intrinsics,
             double config_rate_hz, const BenchOptions& options, std::ostream& log)
      : arm_name_(arm_name), arm_(arm), intrinsics_(intrinsics), options_(options), log_(log) {
    const std::string name = "bench-" + arm_name + "-" + size_text(intrinsics.width, intrinsics.height);
    const std::string scene_config = bench_scene_config(arm_name);
    if (scene_config.empty()) {
      add_campaign_arm_camera(name, config_rate_hz);
    } else {
      add_scene_cameras(scene_config, name, config_rate_hz);
    }
    // What tofguard-renderer draws (its geometry, padding and mesh
    // simplification), not the simulated camera's exact scene.
    scene_ = robot_model::load_scene(config_.robot.urdf_path, config_.environment.urdf_paths,
                                     renderer::scene_options(config_.renderer, config_.robot));
    triangles_ = scene_.num_triangles();
    for (const std::string& joint : cameras_.front().frames->scene().actuated_joint_names)
      joint_names_.push_back(joint);
    check_camera_offset(std::llround(1e6 / config_rate_hz));
    std::vector<ChannelNames> channels;
    for (const BenchCamera& camera : cameras_) channels.push_back(camera.config.channels);
    recorder_ = std::make_unique<ArrivalRecorder>(config_, channels);
    safety_ = std::make_unique<lcm::LCM>(config_.lcm.url);
    images_ = std::make_unique<lcm::LCM>(config_.lcm.image_url);
    if (!safety_->good() || !images_->good()) throw std::runtime_error("cannot open LCM for publishing");
    start_processes(name);
  }

  size_t triangles() const { return triangles_; }
  size_t cameras() const { return cameras_.size(); }

  // Runs `rate_hz` for `seconds` (after a warm-up on the first call) and
  // measures it: a step per camera.
  std::vector<BenchStep> run_step(double rate_hz, double seconds) {
    if (!recorder_) throw std::logic_error("run_step after measure_floors stopped the chain");
    const int64_t frames = std::max<int64_t>(1, std::llround(rate_hz * seconds));
    const ArmPath path = prepare(rate_hz, static_cast<int>(std::min<int64_t>(frames, kMaxPreparedFrames)));
    if (!warm_) warm_up(path);
    {
      const int64_t lead_in_first = next_seq_;
      publish(path, 0, kLeadInFrames);
      wait_for_verdicts(lead_in_first, next_seq_ - 1);
      recorder_->forget_before(next_seq_);
    }
    std::map<std::string, ProcSample> cpu_before;
    for (const auto& [name, p] : processes_) cpu_before[name] = sample_proc(p->pid());
    cpu_before[kBenchProcess] = sample_proc(getpid());
    // (Before the step: the renderer's counts up to the last frame sent
    // before it, the lead-in's; its heartbeats come at 20 Hz.)
    const std::optional<renderer::RendererService::PredictionStats> prediction_before =
        recorder_->renderer_prediction(last_first_camera_utime_, monotonic_us() + 1000000);
    const int64_t start_us = monotonic_us();
    const int64_t first_seq = next_seq_;
    publish(path, kLeadInFrames, frames);
    const int64_t sent_us = monotonic_us();
    const int64_t last_seq = next_seq_ - 1;
    wait_for_verdicts(first_seq, last_seq);
    const int64_t end_us = monotonic_us();
    std::map<std::string, double> cpu_percent;
    for (const auto& [name, p] : processes_) {
      const ProcSample after = sample_proc(p->pid());
      if (!after.alive) throw std::runtime_error(name + " died during the step\n" + stderr_of_all());
      cpu_percent[name] = 100.0 * (after.cpu_s - cpu_before[name].cpu_s) / ((end_us - start_us) * 1e-6);
    }
    cpu_percent[kBenchProcess] = 100.0 * (sample_proc(getpid()).cpu_s - cpu_before[kBenchProcess].cpu_s) /
                                 ((end_us - start_us) * 1e-6);
    std::vector<BenchStep> steps;
    for (const BenchCamera& camera : cameras_) {
      BenchStep step = camera_step(camera, first_seq, last_seq, cpu_percent);
      step.rate_hz = rate_hz;
      step.frames_sent = static_cast<int>(frames);
      step.sent_rate_hz = frames > 1 ? (frames - 1) / ((sent_us - start_us) * 1e-6) : rate_hz;
      steps.push_back(std::move(step));
    }
    if (prediction_before) {
      const auto after = recorder_->renderer_prediction(last_first_camera_utime_, monotonic_us() + 1000000);
      if (after) {
        BenchStep& step = steps.front();
        step.prediction_hits = static_cast<int>(after->hits - prediction_before->hits);
        step.prediction_misses = static_cast<int>(after->misses - prediction_before->misses);
        step.frames_without_prediction = static_cast<int>(after->without - prediction_before->without);
      }
    }
    recorder_->forget_before(next_seq_);
    return steps;
  }

  // One camera's frames [first_seq, last_seq] of a step (their seqs
  // camera.seq_base on): what arrived of each and when; its processes'
  // CPU from `cpu_percent` (by the chain's names), with the shared ones'.
  BenchStep camera_step(const BenchCamera& camera, int64_t first_seq, int64_t last_seq,
                        const std::map<std::string, double>& cpu_percent) {
    BenchStep step;
    step.arm = cameras_.size() > 1 ? arm_name_ + " " + camera.config.camera.id : arm_name_;
    step.width = intrinsics_.width;
    step.height = intrinsics_.height;
    step.triangles = triangles();
    for (const auto& [name, percent] : cpu_percent) {
      const size_t slash = name.find('/');
      if (slash == std::string::npos) {
        step.cpu_percent[name] = percent;  // a shared process, or the one camera's
      } else if (name.substr(slash + 1) == camera.config.camera.id) {  // "<process>/<camera id>"
        step.cpu_percent[name.substr(0, slash)] = percent;
      }
    }
    std::vector<double> render_ms, discrepancy_ms, compute_ms, risk_ms, end_to_end_ms;
    for (int64_t seq = camera.seq_base + first_seq; seq <= camera.seq_base + last_seq; ++seq) {
      const FrameArrivals a = recorder_->arrivals(seq);
      BenchStep::Frame frame;
      frame.seq = seq;
      if (a.rendered_us) frame.render_ms = (a.rendered_us - a.sent_us) * 1e-3;
      if (a.rendered_us && a.discrepancy_us) frame.discrepancy_ms = (a.discrepancy_us - a.rendered_us) * 1e-3;
      if (a.discrepancy_us && a.compute_us >= 0) frame.compute_ms = a.compute_us * 1e-3;
      if (a.discrepancy_us && a.risk_us) frame.risk_ms = (a.risk_us - a.discrepancy_us) * 1e-3;
      if (a.risk_us) frame.end_to_end_ms = (a.risk_us - a.sent_us) * 1e-3;
      step.frames.push_back(frame);
      if (frame.render_ms) render_ms.push_back(*frame.render_ms);
      if (frame.discrepancy_ms) discrepancy_ms.push_back(*frame.discrepancy_ms);
      if (frame.compute_ms) compute_ms.push_back(*frame.compute_ms);
      if (frame.risk_ms) risk_ms.push_back(*frame.risk_ms);
      if (frame.end_to_end_ms) end_to_end_ms.push_back(*frame.end_to_end_ms);
      if (a.rendered_us) ++step.frames_rendered;
      if (a.discrepancy_us) ++step.frames_judged;
      if (a.risk_us) ++step.frames_verdict;
      if (a.risk_us && a.risk_signed) ++step.frames_verdict_signed_first;
      if (a.risk_us && a.level == risk_t::SAFE) ++step.frames_safe;
      if (a.risk_us == 0 || a.risk_us - a.sent_us > options_.result_timeout_us) ++step.frames_dropped;
    }
    step.render = summarise(render_ms);
    step.discrepancy = summarise(discrepancy_ms);
    step.discrepancy_compute = summarise(compute_ms);
    step.risk = summarise(risk_ms);
    step.end_to_end = summarise(end_to_end_ms);
    return step;
  }

  // Stops the chain (its processes and the bench's receiver) and measures
  // the floors alone (BenchFloors): renders and compute_discrepancy along
  // the last step's path, then `hops` messages of each size at `rate_hz`.
  BenchFloors measure_floors(double rate_hz, int hops) {
    BenchFloors f;
    f.arm = arm_name_;
    f.width = intrinsics_.width;
    f.height = intrinsics_.height;
    f.rate_hz = rate_hz;
    f.listeners = options_.floor_listeners;
    const std::vector<std::vector<uint8_t>>& encoded = cameras_.front().encoded;
    f.image_hop.bytes = encoded.empty() ? 0 : encoded.front().size();
    f.discrepancy_hop.bytes = recorder_->largest_message(ArrivalRecorder::Stage::kDiscrepancy);
    f.risk_hop.bytes = recorder_->largest_message(ArrivalRecorder::Stage::kRisk);
    const size_t rendered_bytes = recorder_->largest_message(ArrivalRecorder::Stage::kRendered);
    processes_.clear();
    recorder_.reset();
    log_ << "  floors: chain stopped; " << options_.floor_frames << " renders and compute_discrepancy, then "
         << hops << " LCM hops of each size at " << fixed_text(rate_hz, 0) << " Hz" << std::endl;
    measure_compute_floors(&f);
    if (rendered_bytes != 0 && rendered_bytes != f.image_hop.bytes)
      log_ << "  floors: TOF_RENDERED was " << rendered_bytes << " bytes, TOF_DEPTH " << f.image_hop.bytes
           << "; the image hop uses TOF_DEPTH's size" << std::endl;
    // Without a verdict in the run: the size of the model's own message.
    if (f.discrepancy_hop.bytes == 0) f.discrepancy_hop.bytes = discrepancy_bytes_;
    if (f.risk_hop.bytes == 0) f.risk_hop.bytes = static_cast<size_t>(risk_t{}.getEncodedSize());
    measure_hops(rate_hz, hops, &f);
    return f;
  }

  std::string stderr_of_all() {
    std::string text;
    for (auto& [name, p] : processes_) {
      const std::string err = p->stderr_text();
      text += "--- " + name + ":\n" + (err.size() > 2000 ? err.substr(err.size() - 2000) : err);
    }
    return text;
  }

 private:
  // A campaign arm (config/sim.yaml with its robot, scene and camera, the
  // ideal camera: write_bench_config) at the bench's size and rate: one
  // camera, its frames from the campaign arm's camera.
  void add_campaign_arm_camera(const std::string& name, double config_rate_hz) {
    arm_.config.camera.intrinsics = intrinsics_;
    arm_.config.camera.rate_hz = config_rate_hz;
    auto frames = std::make_unique<SimulatedFrames>(arm_.config);
    // The campaign's generic scenes place the camera in "world", which the
    // campaign resolves itself; tofguard-renderer needs a link of the model:
    // the robot's root link is the world frame (docs/architecture.md).
    const robot_model::SceneModel& scene = frames->scene();
    const CameraPose& pose = arm_.config.camera.pose;
    if (std::none_of(scene.links.begin(), scene.links.end(),
                     [&](const robot_model::Link& l) { return l.name == pose.frame_id; })) {
      arm_.config.camera.pose =
          CameraPose(scene.links.front().name, pose.translation_m, UnitQuaternion(pose.rotation));
    }
    config_path_ = write_bench_config(arm_, intrinsics_, name, options_.joint_prediction);
    config_ = deployment::load_config(config_path_, nullptr);
    BenchCamera camera;
    camera.config = config_;
    camera.config.camera.pose = arm_.config.camera.pose;
    camera.frames = std::move(frames);
    cameras_.push_back(std::move(camera));
  }

  // A deployment of config/ as it is (write_scene_bench_config): each of its
  // cameras imperfect and commissioned, at its own size and rate, its
  // frames from its own simulated camera.
  void add_scene_cameras(const std::string& scene_config, const std::string& name, double config_rate_hz) {
    config_path_ = write_scene_bench_config(scene_config, name, options_.joint_prediction);
    config_ = deployment::load_config(config_path_, nullptr);
    arm_.config = config_;  // the arm's motion
    for (size_t c = 0; c < config_.cameras.size(); ++c) {
      BenchCamera camera;
      const bool several = config_.cameras.size() > 1;
      camera.config = several ? deployment::select_camera(config_, config_.cameras[c].id) : config_;
      const Intrinsics& own = camera.config.camera.intrinsics;
      if (own.width != intrinsics_.width || own.height != intrinsics_.height ||
          camera.config.camera.rate_hz != config_rate_hz) {
        throw std::invalid_argument(
            "--arms " + arm_name_ + ": " + scene_config +
            " runs as it is, at its cameras' own size and rate: " + camera.config.camera.id + " is " +
            size_text(own.width, own.height) + " at " + number_text(camera.config.camera.rate_hz) +
            " Hz, asked " + size_text(intrinsics_.width, intrinsics_.height) + " at " +
            number_text(config_rate_hz) + " Hz");
      }
      camera.frames = std::make_unique<SimulatedFrames>(camera.config);
      camera.seq_base = static_cast<int64_t>(c) * kCameraSeqStride;
      cameras_.push_back(std::move(camera));
    }
  }

  // The judge first, so that it listens before its inputs speak (as
  // LiveChain starts it); with several cameras each camera's renderer and
  // discrepancy process with --camera, as the deployment's launch: section
  // starts them, named "<process>/<camera id>" in processes_.
  void start_processes(const std::string& name) {
    for (const std::string& p : kChainProcesses) {
      const bool per_camera = p == "tofguard-renderer" || p == "tofguard-discrepancy";
      if (!per_camera || cameras_.size() == 1) {
        processes_[p] = std::make_unique<Subprocess>(
            name + "-" + p, std::vector<std::string>{bin_dir() + "/" + p, "--config", config_path_});
        continue;
      }
      for (const BenchCamera& camera : cameras_) {
        const std::string& id = camera.config.camera.id;
        processes_[p + "/" + id] = std::make_unique<Subprocess>(
            name + "-" + p + "-" + id,
            std::vector<std::string>{bin_dir() + "/" + p, "--config", config_path_, "--camera", id});
      }
    }
  }

  // Every camera's frames [first_seq, last_seq] have their verdicts, or
  // result_timeout_us has passed since the last was sent.
  bool wait_for_verdicts(int64_t first_seq, int64_t last_seq) {
    bool all = true;
    for (const BenchCamera& camera : cameras_) {
      all = recorder_->wait_for_verdicts(camera.seq_base + first_seq, camera.seq_base + last_seq,
                                         last_send_us_ + options_.result_timeout_us) &&
            all;
    }
    return all;
  }

  // Renders the step's frames before it starts, so that the publisher only
  // publishes: each simulated ToF camera's pipeline (scene at the arm's
  // pose, noise, mixed and invalid pixels, distance calibration), encoded
  // once. A camera exposing camera_offset_us() after camera 0 gets each
  // frame twice: the arm that much further along the path, and that much
  // back (the path played backwards).
  ArmPath prepare(double rate_hz, int count) {
    ArmPath path;
    path.rate_hz = rate_hz;
    path.prepared = count;
    path.start_s = motion_start_s_;
    // The next step starts elsewhere on the arm's path.
    motion_start_s_ += 1.7;
    last_path_ = path;
    for (size_t c = 0; c < cameras_.size(); ++c) {
      BenchCamera& camera = cameras_[c];
      const double offset_s = camera_offset_us(c) * 1e-6;
      camera.encoded = prepare_frames(camera, path, offset_s);
      camera.encoded_behind.clear();
      if (offset_s > 0) camera.encoded_behind = prepare_frames(camera, path, -offset_s);
    }
    return path;
  }

  std::vector<std::vector<uint8_t>> prepare_frames(BenchCamera& camera, const ArmPath& path,
                                                   double offset_s) {
    std::vector<std::vector<uint8_t>> encoded;
    const Eigen::Isometry3d world_from_optical = camera.config.camera.pose.frame_from_optical();
    const Intrinsics& intrinsics = camera.config.camera.intrinsics;
    for (int i = 0; i < path.prepared; ++i) {
      const std::vector<float> depth_m =
          camera.frames->capture(joints_at(path.start_s + i / path.rate_hz + offset_s), world_from_optical,
                                 intrinsics, ++noise_index_);
      const depth_image_t image =
          make_depth_image(camera.config.camera.id, intrinsics, 0, 0, /*calibrated=*/true, depth_m);
      std::vector<uint8_t> bytes(static_cast<size_t>(image.getEncodedSize()));
      if (image.encode(bytes.data(), 0, static_cast<int>(bytes.size())) < 0)
        throw std::runtime_error("cannot encode a depth frame");
      encoded.push_back(std::move(bytes));
    }
    return encoded;
  }

  // Every camera exposes within the frame period less 2 ms (its joint
  // state 1 ms before, the next slot's after); throws
  // std::invalid_argument otherwise.
  void check_camera_offset(int64_t period_us) const {
    if (static_cast<int64_t>(cameras_.size() - 1) * camera_offset_us(1) > period_us - 2000)
      throw std::invalid_argument("--camera-offset-ms " + number_text(options_.camera_offset_ms) + ": " +
                                  std::to_string(cameras_.size()) + " cameras must expose within the " +
                                  number_text(period_us * 1e-3) + " ms period less 2 ms");
  }

  // When camera c exposes after camera 0, microseconds.
  int64_t camera_offset_us(size_t c) const {
    return static_cast<int64_t>(c) * std::llround(options_.camera_offset_ms * 1000);
  }

  // Camera c's prepared frame for path index `index` exposed at `t_s` on the
  // path (the arm at path.at(t_s)): the one made at that motion time.
  std::vector<uint8_t>& frame_at(size_t c, const ArmPath& path, int index, double t_s) {
    BenchCamera& camera = cameras_[c];
    if (camera.encoded_behind.empty()) return camera.encoded[static_cast<size_t>(index)];
    // (The slots are whole microseconds apart, the prepared frames 1 /
    // rate_hz: the two drift apart by under a microsecond a frame.)
    const double motion_s = path.at(t_s).first;
    const double ahead_s = path.start_s + index / path.rate_hz + camera_offset_us(c) * 1e-6;
    const double behind_s = path.start_s + index / path.rate_hz - camera_offset_us(c) * 1e-6;
    const double off_ahead_s = std::abs(motion_s - ahead_s), off_behind_s = std::abs(motion_s - behind_s);
    if (std::min(off_ahead_s, off_behind_s) < 1e-3)
      return off_ahead_s <= off_behind_s ? camera.encoded[static_cast<size_t>(index)]
                                         : camera.encoded_behind[static_cast<size_t>(index)];
    throw std::logic_error("no prepared frame of " + camera.config.camera.id + " at motion time " +
                           std::to_string(motion_s) + " s (index " + std::to_string(index) + ")");
  }

  robot_model::JointPositions joints_at(double motion_s) const {
    robot_model::JointPositions joints;
    for (const std::string& j : joint_names_) joints[j] = 0;
    for (const sim::JointMotion& m : arm_.config.joints_sim.motion)
      joints[m.joint] = joint_position(m, motion_s);
    return joints;
  }

  joint_state_t joint_state(const ArmPath& path, double t_s, int64_t utime) const {
    const auto [motion_s, direction] = path.at(t_s);
    joint_state_t s;
    s.utime = utime;
    s.robot_id = config_.robot.id;
    for (const std::string& j : joint_names_) {
      double position = 0, velocity = 0;
      for (const sim::JointMotion& m : arm_.config.joints_sim.motion) {
        if (m.joint != j) continue;
        position = joint_position(m, motion_s);
        velocity = direction * joint_velocity(m, motion_s);
      }
      s.name.push_back(j);
      s.position.push_back(position);
      s.velocity.push_back(velocity);
    }
    s.num_joints = static_cast<int32_t>(s.name.size());
    return s;
  }

  // One thing publish() sends, at_us after its start: a joint state (at
  // utime_us), the plan's chunk from slot k, or camera `camera`'s frame of
  // slot k (captured at utime_us).
  struct Send {
    enum class Kind { kJointState, kPlan, kFrame };
    Kind kind = Kind::kJointState;
    int64_t at_us = 0;
    int64_t utime_us = 0;
    int64_t k = 0;
    size_t camera = 0;
  };

  // What publish() sends, in time order: before slot k the joint states
  // since the last slot (every 10 ms) and, 1 ms before each camera's
  // exposure, one at the exposure's own utime, so that the renderer
  // interpolates, never extrapolates (docs/renderer.md). JOINT_STATE
  // (safety URL) and TOF_DEPTH (image URL) arrive on separate sockets, and
  // a frame that came first would be rendered at joints extrapolated from
  // the states before it. In the warm-up (one frame a call, no states in
  // between, the path a period ahead per frame whatever the clock) that
  // extrapolation was off by degrees: an encoder error the risk's
  // sequential test then carried into the measured step's first frames
  // (270-290 SAFE of 300 in some runs). A 10 ms state within that last
  // millisecond before an exposure is left out: the states' utimes rise.
  std::vector<Send> schedule(int64_t period_us, int64_t frames) const {
    check_camera_offset(period_us);
    std::vector<int64_t> exposures_us;
    for (int64_t k = 0; k < frames; ++k)
      for (size_t c = 0; c < cameras_.size(); ++c)
        exposures_us.push_back(k * period_us + camera_offset_us(c));
    const auto just_before_an_exposure = [&](int64_t j) {
      return std::any_of(exposures_us.begin(), exposures_us.end(),
                         [j](int64_t e) { return e - 1000 <= j && j <= e; });
    };
    std::vector<Send> sends;
    for (int64_t k = 0; k < frames; ++k) {
      const int64_t slot_us = k * period_us;
      for (int64_t j = slot_us - period_us + kJointStatePeriodUs; k > 0 && j < slot_us - 1000;
           j += kJointStatePeriodUs) {
        if (!just_before_an_exposure(j)) sends.push_back({Send::Kind::kJointState, j, j, k, 0});
      }
      if (options_.plan && k % kPlanChunkFrames == 0)
        sends.push_back({Send::Kind::kPlan, slot_us - 1000, 0, k, 0});
      for (size_t c = 0; c < cameras_.size(); ++c) {
        const int64_t exposure_us = slot_us + camera_offset_us(c);
        // (Cameras exposing at the same instant share its state.)
        if (c == 0 || camera_offset_us(c) != camera_offset_us(c - 1))
          sends.push_back({Send::Kind::kJointState, exposure_us - 1000, exposure_us, k, c});
        sends.push_back({Send::Kind::kFrame, exposure_us, exposure_us, k, c});
      }
    }
    std::stable_sort(sends.begin(), sends.end(),
                     [](const Send& a, const Send& b) { return a.at_us < b.at_us; });
    return sends;
  }

  // Publishes `frames` frames of every camera at path.rate_hz on the
  // monotonic clock, with the joint states around them (schedule()).
  // `first_k`: the first frame's index on the path (the warm-up goes on
  // along it one frame per call).
  void publish(const ArmPath& path, int64_t first_k, int64_t frames) {
    const int64_t period_us = std::llround(1e6 / path.rate_hz);
    const std::vector<Send> sends = schedule(period_us, frames);
    const int64_t start_mono_us = monotonic_us() + 2000;
    // utimes continue the wall clock (capture time = the time it is sent),
    // and always rise across steps.
    const int64_t start_utime = std::max(wall_utime(), last_utime_ + 1000) + 2000;
    const int64_t first_seq = next_seq_;
    for (const Send& send : sends) {
      std::this_thread::sleep_until(
          std::chrono::steady_clock::time_point(std::chrono::microseconds(start_mono_us + send.at_us)));
      const int64_t utime = start_utime + send.utime_us;
      const double t_s = (first_k * period_us + send.utime_us) * 1e-6;  // on the path
      if (send.kind == Send::Kind::kPlan) {
        publish_plan(path, first_k, send.k, frames, start_utime);
      } else if (send.kind == Send::Kind::kJointState) {
        const joint_state_t state = joint_state(path, t_s, utime);
        safety_->publish(config_.channels.joint_state, &state);
      } else {
        const BenchCamera& camera = cameras_[send.camera];
        std::vector<uint8_t>& bytes = frame_at(send.camera, path, path.index(first_k + send.k), t_s);
        const int64_t seq = camera.seq_base + first_seq + send.k;
        put_int64_be(bytes.data() + kUtimeOffset, utime);
        put_int64_be(bytes.data() + kSeqOffset, seq);
        recorder_->sent(seq, monotonic_us());
        images_->publish(camera.config.channels.depth, bytes.data(), static_cast<unsigned int>(bytes.size()));
        last_send_us_ = monotonic_us();
        last_utime_ = std::max(last_utime_, utime);
        if (send.camera == 0) last_first_camera_utime_ = utime;
      }
    }
    next_seq_ = first_seq + frames;
  }

  // The plan's chunk from frame k of a publish() call on: a point at each
  // frame's capture time up to 2 * kPlanChunkFrames frames ahead (at most
  // one past the call's last frame), the joints as that frame's own
  // JOINT_STATE has them.
  void publish_plan(const ArmPath& path, int64_t first_k, int64_t k, int64_t frames, int64_t start_utime) {
    const int64_t period_us = std::llround(1e6 / path.rate_hz);
    planned_trajectory_t plan;
    plan.utime = wall_utime();
    plan.joint_name = joint_names_;
    plan.num_joints = static_cast<int32_t>(joint_names_.size());
    for (int64_t i = k; i <= std::min(k + 2 * kPlanChunkFrames, frames); ++i) {
      const int64_t utime = start_utime + i * period_us;
      plan.point_utime.push_back(utime);
      plan.position.push_back(joint_state(path, (first_k + i) * period_us * 1e-6, utime).position);
    }
    plan.num_points = static_cast<int32_t>(plan.point_utime.size());
    safety_->publish(config_.channels.planned_trajectory, &plan);
  }

  // Publishes until kWarmupFrames frames in a row have come through the
  // whole chain (the processes loaded their models and paired their first
  // inputs), then lets the rest drain.
  void warm_up(const ArmPath& path) {
    log_ << "  starting the chain (" << arm_name_ << ", " << size_text(intrinsics_.width, intrinsics_.height)
         << ", " << triangles() << " triangles)..." << std::endl;
    const int64_t first_seq = next_seq_;
    const int64_t deadline_us =
        monotonic_us() + std::chrono::duration_cast<std::chrono::microseconds>(kStartDeadline).count();
    // One frame at a time: each waits for its verdict (or 1 s), so that the
    // chain is not flooded while it starts.
    int in_a_row = 0;
    while (in_a_row < kWarmupFrames) {
      if (monotonic_us() > deadline_us)
        throw std::runtime_error("the chain did not judge " + std::to_string(kWarmupFrames) +
                                 " frames in a row within " + std::to_string(kStartDeadline.count()) +
                                 " s\n" + stderr_of_all());
      for (auto& [name, p] : processes_) {
        if (!p->running()) throw std::runtime_error(name + " exited at start\n" + stderr_of_all());
      }
      publish(path, next_seq_ - first_seq, 1);
      // With several cameras, while the verdict is not SAFE (the start's
      // deadlines) tofguard-risk publishes the camera longest DANGEROUS,
      // with that camera's seq: a verdict for any camera's frame of the
      // slot shows the chain through.
      std::vector<int64_t> seqs;
      for (const BenchCamera& camera : cameras_) seqs.push_back(camera.seq_base + next_seq_ - 1);
      in_a_row = recorder_->wait_for_any_verdict(seqs, monotonic_us() + options_.result_timeout_us)
                     ? in_a_row + 1
                     : 0;
    }
    recorder_->forget_before(next_seq_);
    log_ << "  chain up after " << next_seq_ - first_seq << " frames" << std::endl;
    warm_ = true;
  }

  void measure_compute_floors(BenchFloors* f) {
    const std::vector<std::vector<uint8_t>>& encoded = cameras_.front().encoded;
    if (encoded.empty()) return;
    renderer::DepthRenderer renderer(scene_, config_.renderer.near_m, config_.renderer.far_m);
    const CameraPose& pose = config_.camera.pose;
    const auto joints = [&](int i) {
      return joints_at(last_path_.start_s + last_path_.index(i) / last_path_.rate_hz);
    };
    const int n = std::max(1, options_.floor_frames);
    log_ << "  floors: rendering with " << renderer.description() << std::endl;
    // Untimed: the first renders (shaders, buffers).
    for (int i = 0; i < 3; ++i) renderer.render(joints(i), pose, intrinsics_);
    std::vector<double> render_ms;
    for (int i = 0; i < n; ++i) {
      const robot_model::JointPositions j = joints(i);
      const int64_t start_us = monotonic_us();
      const renderer::RenderResult result = renderer.render(j, pose, intrinsics_);
      const int64_t end_us = monotonic_us();
      if (!result.usable)
        throw std::runtime_error("floors: the scene cannot be rendered: " + result.unusable_reason);
      render_ms.push_back((end_us - start_us) * 1e-3);
    }
    f->render = summarise(render_ms);
    // compute_discrepancy on each prepared camera frame and the model at
    // its joints, as tofguard-renderer makes TOF_RENDERED and TOF_LABELS.
    const robot_model::ArmSpheres cover =
        robot_model::cover_arm_with_spheres(scene_, config_.renderer.arm_cover_cell_m);
    const discrepancy::DiscrepancyOptions discrepancy_options =
        discrepancy::discrepancy_options(config_.discrepancy);
    WorkerPool workers(config_.discrepancy.worker_threads);
    std::vector<double> compute_ms;
    // A digest (FNV-1a) of every summary computed, utime and compute_us
    // aside: a change made for speed alone must leave it as it was
    // (docs/benchmarks.md, "The hot paths").
    uint64_t digest = 0xcbf29ce484222325ULL;
    for (int i = 0; i < n; ++i) {
      const std::vector<uint8_t>& bytes = encoded[static_cast<size_t>(last_path_.index(i))];
      depth_image_t camera;
      if (camera.decode(bytes.data(), 0, static_cast<int>(bytes.size())) < 0)
        throw std::runtime_error("floors: cannot decode a prepared frame");
      const renderer::RenderResult result = renderer.render(joints(i), pose, intrinsics_);
      const depth_image_t rendered = make_depth_image(camera.camera_id, intrinsics_of(camera), camera.utime,
                                                      camera.seq, /*calibrated=*/true, result.depth_m);
      const link_labels_t labels = renderer::make_rendered_link_labels(camera, result, scene_, cover);
      const int64_t start_us = monotonic_us();
      const discrepancy::DiscrepancyFrame frame =
          discrepancy::compute_discrepancy(camera, rendered, labels, discrepancy_options, &workers);
      const int64_t end_us = monotonic_us();
      if (!frame.summary.usable) {
        log_ << "  floors: compute_discrepancy: unusable: " << frame.summary.unusable_reason << std::endl;
        continue;
      }
      discrepancy_bytes_ = std::max(discrepancy_bytes_, static_cast<size_t>(frame.summary.getEncodedSize()));
      compute_ms.push_back((end_us - start_us) * 1e-3);
      discrepancy_t summary = frame.summary;
      summary.utime = 0;
      summary.compute_us = 0;
      std::vector<uint8_t> encoded(static_cast<size_t>(summary.getEncodedSize()));
      summary.encode(encoded.data(), 0, static_cast<int>(encoded.size()));
      for (uint8_t byte : encoded) digest = (digest ^ byte) * 0x100000001b3ULL;
    }
    f->discrepancy_compute = summarise(compute_ms);
    log_ << "  floors: compute_discrepancy on " << compute_ms.size() << " frames, digest of the summaries "
         << std::hex << digest << std::dec << std::endl;
  }

  // Each period five messages a fifth of a period apart, through the
  // publishers the chain's frames went through: an image-sized hop on the
  // image URL, the discrepancy relay's image-sized message in (image URL),
  // a discrepancy_t-sized hop, the risk relay's discrepancy_t-sized message
  // in, a risk_t-sized hop (safety URL).
  void measure_hops(double rate_hz, int hops, BenchFloors* f) {
    const size_t relay_out_bytes[2] = {f->discrepancy_hop.bytes, f->risk_hop.bytes};
    HopReceiver receiver(config_.lcm.url, config_.lcm.image_url);
    HopRelay relay(config_.lcm.url, config_.lcm.image_url, relay_out_bytes);
    // Joined after the receiver and the relay, as the chain's processes
    // joined after the bench's receiver: the kernel delivers to the newest
    // socket of a port first.
    std::vector<std::unique_ptr<IdleListener>> listeners;
    for (int i = 0; i < f->listeners; ++i)
      listeners.push_back(std::make_unique<IdleListener>(config_.lcm.url, config_.lcm.image_url));
    HopFloor* floors[3] = {&f->image_hop, &f->discrepancy_hop, &f->risk_hop};
    RelayFloor* relays[2] = {&f->discrepancy_relay, &f->risk_relay};
    // Message m of the period: its kind, floor or relay, URL and channel.
    struct Message {
      std::vector<uint8_t> bytes;
      int* sent;
      lcm::LCM* url;
      const std::string* channel;
    };
    std::vector<Message> messages;
    const auto add = [&](int64_t kind, size_t size, int* sent, lcm::LCM* url, const std::string& channel) {
      Message m{std::vector<uint8_t>(std::max(size, kHopHeaderBytes), 0), sent, url, &channel};
      put_int64_be(m.bytes.data(), kind);
      messages.push_back(std::move(m));
      return messages.back().bytes.size();
    };
    floors[0]->bytes = add(0, floors[0]->bytes, &floors[0]->sent, images_.get(), kHopChannels[0]);
    relays[0]->in_bytes =
        add(kRelayInKind, floors[0]->bytes, &relays[0]->sent, images_.get(), kRelayInChannels[0]);
    floors[1]->bytes = add(1, floors[1]->bytes, &floors[1]->sent, safety_.get(), kHopChannels[1]);
    relays[1]->in_bytes =
        add(kRelayInKind + 1, floors[1]->bytes, &relays[1]->sent, safety_.get(), kRelayInChannels[1]);
    floors[2]->bytes = add(2, floors[2]->bytes, &floors[2]->sent, safety_.get(), kHopChannels[2]);
    for (int r = 0; r < 2; ++r) relays[r]->out_bytes = std::max(relay_out_bytes[r], kHopHeaderBytes);
    // (The receiver's and the relay's sockets joined their groups when they
    // were constructed: nothing sent from here on is missed.)
    const int64_t period_us = std::llround(1e6 / rate_hz);
    const int64_t start_mono_us = monotonic_us() + 2000;
    const int count = static_cast<int>(messages.size());
    for (int k = 0; k < hops; ++k) {
      for (int m = 0; m < count; ++m) {
        std::this_thread::sleep_until(std::chrono::steady_clock::time_point(
            std::chrono::microseconds(start_mono_us + k * period_us + m * period_us / count)));
        Message& message = messages[static_cast<size_t>(m)];
        put_int64_be(message.bytes.data() + 8, monotonic_us());
        put_int64_be(message.bytes.data() + 16, k);
        message.url->publish(*message.channel, message.bytes.data(),
                             static_cast<unsigned int>(message.bytes.size()));
        ++*message.sent;
      }
    }
    // Each hop once, each relay's message in and out.
    const size_t expected = static_cast<size_t>(7 * hops);
    const int64_t deadline_us = monotonic_us() + options_.result_timeout_us;
    while (receiver.received() < expected && monotonic_us() < deadline_us)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    for (int kind = 0; kind < 3; ++kind) floors[kind]->latency = summarise(receiver.latency_ms(kind));
    for (int r = 0; r < 2; ++r) relays[r]->latency = summarise(receiver.relay_latency_ms(r));
  }

  std::string arm_name_;
  CampaignArm arm_;
  Intrinsics intrinsics_;
  BenchOptions options_;
  std::ostream& log_;
  std::string config_path_;
  deployment::Config config_;
  // Camera 0 is config_'s first camera (its channels config_.channels).
  std::vector<BenchCamera> cameras_;
  std::vector<std::string> joint_names_;
  size_t triangles_ = 0;
  // What tofguard-renderer loads (the floors render it).
  robot_model::SceneModel scene_;
  ArmPath last_path_;
  size_t discrepancy_bytes_ = 0;
  std::unique_ptr<ArrivalRecorder> recorder_;
  std::unique_ptr<lcm::LCM> safety_;
  std::unique_ptr<lcm::LCM> images_;
  std::map<std::string, std::unique_ptr<Subprocess>> processes_;
  int64_t next_seq_ = 1;
  int64_t last_send_us_ = 0;
  int64_t last_utime_ = 0;               // the newest frame's utime sent (any camera's)
  int64_t last_first_camera_utime_ = 0;  // camera 0's newest frame (its renderer's heartbeats say it)
  uint64_t noise_index_ = 0;
  double motion_start_s_ = 0;
  bool warm_ = false;
};

std::string machine_text() {
  std::string model = "unknown CPU";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  std::ifstream loadavg("/proc/loadavg");
  std::string load_1, load_5, load_15;
  loadavg >> load_1 >> load_5 >> load_15;
  return "nproc " + std::to_string(sysconf(_SC_NPROCESSORS_ONLN)) + ", " + model + ", load average " +
         load_1 + " " + load_5 + " " + load_15 + " at the start";
}

std::string date_text() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[64];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M UTC", &utc);
  return text;
}

// Why `step` does not sustain its rate, "" when it does.
std::string not_sustained_because(const BenchStep& step) {
  const double period_ms = 1000.0 / step.rate_hz;
  if (step.frames_dropped > 0) return std::to_string(step.frames_dropped) + " frames dropped";
  if (step.sent_rate_hz < 0.95 * step.rate_hz)
    return "the bench published only " + fixed_text(step.sent_rate_hz, 0) + " Hz";
  const std::pair<const char*, const LatencySummary*> stages[] = {
      {"render", &step.render}, {"discrepancy", &step.discrepancy}, {"risk", &step.risk}};
  for (const auto& [name, s] : stages) {
    if (s->p99_ms > period_ms)
      return std::string(name) + " p99 " + fixed_text(s->p99_ms, 1) + " ms > period " +
             fixed_text(period_ms, 1) + " ms";
  }
  return "";
}

}  // namespace

std::string bench_scene_config(const std::string& arm_name) {
  if (arm_name == "sim") return "config/sim.yaml";
  if (arm_name == "two-cameras") return "config/sim-two-cameras.yaml";
  return "";
}

std::string write_scene_bench_config(const std::string& scene_config, const std::string& name,
                                     bool joint_prediction) {
  const std::vector<std::pair<std::string, std::string>> bench = {
      {"required_heartbeats: [tofguard-camera, tofguard-renderer, tofguard-discrepancy]",
       "required_heartbeats: [tofguard-renderer, tofguard-discrepancy]"},
      {"estimate:\n    enabled: true", "estimate:\n    enabled: false"},
      {"from_joint_states: true", joint_prediction ? "from_joint_states: true" : "from_joint_states: false"}};
  return config_variant(source_dir() + "/" + scene_config, name, bench, "occupant: ~\n");
}

std::optional<CampaignArm> bench_arm(const std::string& name, const std::string& shared_dir,
                                     const std::string& scene_dir) {
  if (name == "default") return default_campaign_arm();
  // (The chain runs the config file; the arm gives the size asked of it.)
  if (!bench_scene_config(name).empty()) return default_campaign_arm();
  if (name == "iiwa14") return iiwa14_campaign_arm(shared_dir, scene_dir);
  if (name == "kinova") return kinova_gen3_campaign_arm(shared_dir, scene_dir);
  throw std::invalid_argument("--arms: expected default, iiwa14, kinova, sim or two-cameras, got '" + name +
                              "'");
}

std::string write_bench_config(const CampaignArm& arm, const Intrinsics& intrinsics, const std::string& name,
                               bool joint_prediction) {
  const deployment::Config& c = arm.config;
  std::string robot = "urdf: " + c.robot.urdf_path;
  if (!c.robot.package_paths.empty()) {
    robot += "\n  package_paths: [";
    for (size_t i = 0; i < c.robot.package_paths.size(); ++i)
      robot += (i ? ", " : "") + c.robot.package_paths[i];
    robot += "]";
  }
  std::string environment = "urdfs: [";
  for (size_t i = 0; i < c.environment.urdf_paths.size(); ++i)
    environment += (i ? ", " : "") + c.environment.urdf_paths[i];
  environment += "]";
  const CameraPose& pose = c.camera.pose;
  const Eigen::Quaterniond q = pose.rotation;
  // The bench's frames are the campaign arm's ideal camera's, at sizes no
  // profile was commissioned for: the ideal camera's lines, no profile (a
  // profile costs one pass over the frame's pixels).
  std::vector<std::pair<std::string, std::string>> replacements = ideal_camera_replacements();
  const std::vector<std::pair<std::string, std::string>> bench = {
      {"urdf: models/friend_arm.urdf", robot},
      {"urdfs: [models/wheelchair_environment.urdf]", environment},
      {"rate_hz: 30\n  intrinsics: {width: 176, height: 144, fx: 221.0, fy: 220.5, cx: 87.3, cy: 71.8}",
       "rate_hz: " + number_text(c.camera.rate_hz) + "\n  intrinsics: {width: " +
           std::to_string(intrinsics.width) + ", height: " + std::to_string(intrinsics.height) +
           ", fx: " + number_text(intrinsics.fx) + ", fy: " + number_text(intrinsics.fy) +
           ", cx: " + number_text(intrinsics.cx) + ", cy: " + number_text(intrinsics.cy) + "}"},
      {"frame: world\n    translation_m: [-0.90, -0.20, 1.80]\n    rotation_wxyz: [0.302934347, "
       "-0.581931466, "
       "0.669435574, -0.348486102]",
       "frame: " + pose.frame_id + "\n    translation_m: [" + number_text(pose.translation_m.x()) + ", " +
           number_text(pose.translation_m.y()) + ", " + number_text(pose.translation_m.z()) +
           "]\n    rotation_wxyz: [" + number_text(q.w()) + ", " + number_text(q.x()) + ", " +
           number_text(q.y()) + ", " + number_text(q.z()) + "]"},
      // The bench stands in for tofguard-camera (it publishes the frames,
      // not a heartbeat), and no tofguard-estimator runs: the observer
      // chain alone, judged by its rules.
      {"required_heartbeats: [tofguard-camera, tofguard-renderer, tofguard-discrepancy]",
       "required_heartbeats: [tofguard-renderer, tofguard-discrepancy]"},
      {"estimate:\n    enabled: true", "estimate:\n    enabled: false"},
      {"from_joint_states: true", joint_prediction ? "from_joint_states: true" : "from_joint_states: false"}};
  replacements.insert(replacements.end(), bench.begin(), bench.end());
  // The bench's frames (SimulatedFrames) show no wheelchair user: the
  // chain models none.
  return sim_config_variant(name, replacements, "occupant: ~\n");
}

BenchReport run_bench(const BenchOptions& options, std::ostream& log) {
  BenchReport report;
  report.machine = machine_text();
  report.date = date_text();
  report.options = options;
  const std::string scene_dir = options.work_dir.empty() ? output_dir() + "/bench" : options.work_dir;
  for (const std::string& arm_name : options.arms) {
    const std::optional<CampaignArm> arm = bench_arm(arm_name, options.shared_dir, scene_dir);
    if (!arm) {
      report.skipped.push_back(
          arm_name + ": skipped, its URDF is not under " +
          (options.shared_dir.empty() ? std::string("../shared (absent)") : options.shared_dir + "/robots"));
      log << report.skipped.back() << std::endl;
      continue;
    }
    for (const auto& [width, height] : options.resolutions) {
      const Intrinsics intrinsics = scaled_intrinsics(arm->config.camera.intrinsics, width, height);
      log << arm_name << " " << size_text(width, height) << std::endl;
      BenchChain chain(arm_name, *arm, intrinsics, options.ramp ? options.ramp_start_hz : options.rate_hz,
                       options, log);
      // The floors' hops: as many as the run's frames (30 to 300) at its rate.
      const auto floor_hops = [](double rate_hz, double seconds) {
        return static_cast<int>(std::clamp<int64_t>(std::llround(rate_hz * seconds), 30, 300));
      };
      // The floors are one camera's stages alone.
      const bool floors = options.floors && chain.cameras() == 1;
      if (options.floors && !floors) log << "  floors: not measured with several cameras" << std::endl;
      if (!options.ramp) {
        for (BenchStep& step : chain.run_step(options.rate_hz, options.seconds))
          report.steps.push_back(std::move(step));
        if (floors)
          report.floors.push_back(
              chain.measure_floors(options.rate_hz, floor_hops(options.rate_hz, options.seconds)));
        continue;
      }
      if (chain.cameras() > 1) throw std::invalid_argument("--ramp: with one camera only, not " + arm_name);
      BenchRamp ramp;
      ramp.arm = arm_name;
      ramp.width = width;
      ramp.height = height;
      ramp.triangles = chain.triangles();
      // Whether `rate` is sustained; if not, why (stopped_because).
      const auto sustains = [&](double rate) {
        log << "  " << fixed_text(rate, 0) << " Hz for " << options.ramp_step_s << " s" << std::endl;
        ramp.steps.push_back(chain.run_step(rate, options.ramp_step_s).front());
        const std::string why = not_sustained_because(ramp.steps.back());
        if (why.empty()) return true;
        ramp.stopped_because = fixed_text(rate, 0) + " Hz: " + why;
        return false;
      };
      double failed_hz = 0;
      for (double rate = options.ramp_start_hz; rate <= options.ramp_max_hz; rate *= 2) {
        if (!sustains(rate)) {
          failed_hz = rate;
          break;
        }
        ramp.sustained_hz = rate;
      }
      // Between the last rate sustained and the first not, halving the gap
      // (240 and 480 Hz: 360, then 300 or 420), whole Hz.
      for (int k = 0; k < options.ramp_refinements && ramp.sustained_hz > 0 && failed_hz > 0; ++k) {
        const double rate = std::round((ramp.sustained_hz + failed_hz) / 2);
        if (rate <= ramp.sustained_hz || rate >= failed_hz) break;
        // (stopped_because stays the lowest rate not sustained.)
        if (sustains(rate)) {
          ramp.sustained_hz = rate;
        } else {
          failed_hz = rate;
        }
      }
      if (ramp.stopped_because.empty())
        ramp.stopped_because = "none up to " + fixed_text(options.ramp_max_hz, 0) + " Hz (the ramp's end)";
      report.ramps.push_back(std::move(ramp));
      if (floors)
        report.floors.push_back(chain.measure_floors(options.ramp_start_hz,
                                                     floor_hops(options.ramp_start_hz, options.ramp_step_s)));
    }
  }
  return report;
}

namespace {

std::string latency_cell(const LatencySummary& s, int decimals = 1) {
  if (s.count == 0) return "-";
  return fixed_text(s.p50_ms, decimals) + " / " + fixed_text(s.p99_ms, decimals) + " / " +
         fixed_text(s.max_ms, decimals);
}

std::string steps_table(const std::vector<BenchStep>& steps) {
  const deployment::Config config = deployment::load_config(source_dir() + "/config/sim.yaml", nullptr);
  const ChannelNames& ch = config.channels;
  std::ostringstream t;
  t << "| arm | triangles | size | rate (Hz) | sent | dropped | SAFE | " << ch.depth << " → " << ch.rendered
    << " | " << ch.rendered << " → " << ch.discrepancy << " | " << ch.discrepancy << " → " << ch.risk << " | "
    << ch.depth << " → " << ch.risk
    << " (end to end) | CPU % renderer / discrepancy / risk / intervene / bench |\n";
  t << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const BenchStep& s : steps) {
    const auto cpu = [&](const std::string& p) {
      const auto it = s.cpu_percent.find(p);
      return it == s.cpu_percent.end() ? std::string("-") : fixed_text(it->second, 0);
    };
    t << "| " << s.arm << " | " << s.triangles << " | " << size_text(s.width, s.height) << " | "
      << fixed_text(s.rate_hz, 0) << " | " << s.frames_sent << " | " << s.frames_dropped << " | "
      << s.frames_safe << " | " << latency_cell(s.render) << " | " << latency_cell(s.discrepancy) << " | "
      << latency_cell(s.risk) << " | " << latency_cell(s.end_to_end) << " | " << cpu("tofguard-renderer")
      << " / " << cpu("tofguard-discrepancy") << " / " << cpu("tofguard-risk") << " / "
      << cpu("tofguard-intervene") << " / " << cpu(kBenchProcess) << " |\n";
  }
  return t.str();
}

// A list under `heading`, a line per step that `line` says something of
// ("" for none): "- arm, size, rate Hz: " and what it says. "" when no step
// has a line.
std::string step_lines(const std::vector<BenchStep>& steps, const std::string& heading,
                       const std::function<std::string(const BenchStep&)>& line) {
  std::ostringstream t;
  for (const BenchStep& s : steps) {
    const std::string what = line(s);
    if (what.empty()) continue;
    t << "- " << s.arm << ", " << size_text(s.width, s.height) << ", " << fixed_text(s.rate_hz, 0)
      << " Hz: " << what << "\n";
  }
  const std::string lines = t.str();
  return lines.empty() ? lines : "\n" + heading + "\n\n" + lines;
}

// tofguard-discrepancy's own compute_discrepancy time per step.
std::string compute_lines(const std::vector<BenchStep>& steps) {
  return step_lines(
      steps,
      "compute_discrepancy in tofguard-discrepancy (SAFETY_DISCREPANCY's compute_us, p50 / p99 / "
      "max ms; the rest of the discrepancy stage is delivery, decoding, pairing, waiting for a "
      "core and publishing):",
      [](const BenchStep& s) {
        if (s.discrepancy_compute.count == 0) return std::string();
        return latency_cell(s.discrepancy_compute) + " (" + std::to_string(s.discrepancy_compute.count) +
               " frames)";
      });
}

// tofguard-renderer's prediction per step: from the plan (--plan), else
// from the joint states (unless --no-joint-prediction).
std::string prediction_lines(const std::vector<BenchStep>& steps, const BenchOptions& options) {
  const std::string source = options.plan ? "the plan" : "the joint states";
  const std::string heading =
      options.plan ? "With the arm's path published as its plan (PLANNED_TRAJECTORY, --plan; counts from "
                     "tofguard-renderer's heartbeats before and after each step):"
      : options.joint_prediction
          ? "Without a plan, each next frame guessed from the joint states "
            "(renderer.prediction.from_joint_states; counts from tofguard-renderer's heartbeats before and "
            "after each step):"
          : "Without a plan or the joint states' guess (--no-joint-prediction; counts from "
            "tofguard-renderer's heartbeats before and after each step):";
  return step_lines(steps, heading, [source](const BenchStep& s) {
    if (s.prediction_hits < 0) return std::string();
    return "tofguard-renderer rendered " + std::to_string(s.prediction_hits) + " of " +
           std::to_string(s.frames_sent) + " frames ahead from " + source + " (hits), " +
           std::to_string(s.prediction_misses) + " ahead but not within the tolerances (misses), " +
           std::to_string(s.frames_without_prediction) + " without a prediction";
  });
}

std::string hop_cell(const HopFloor& h) {
  std::string cell = latency_cell(h.latency, 2) + " (" + std::to_string(h.bytes) + " B";
  if (h.latency.count != h.sent)
    cell += ", " + std::to_string(h.latency.count) + " of " + std::to_string(h.sent) + " arrived";
  return cell + ")";
}

std::string relay_cell(const RelayFloor& r) {
  std::string cell = latency_cell(r.latency, 2) + " (" + std::to_string(r.in_bytes) + " → " +
                     std::to_string(r.out_bytes) + " B";
  if (r.latency.count != r.sent)
    cell += ", " + std::to_string(r.latency.count) + " of " + std::to_string(r.sent) + " relayed";
  return cell + ")";
}

// "1.4× (4.1 / 2.9 ms)": the stage's p50 over its floor.
std::string ratio_cell(const LatencySummary& stage, double floor_ms) {
  if (stage.count == 0 || !(floor_ms > 0)) return "-";
  return fixed_text(stage.p50_ms / floor_ms, 1) + "× (" + fixed_text(stage.p50_ms, 2) + " / " +
         fixed_text(floor_ms, 2) + " ms)";
}

std::string floors_table(const BenchReport& report) {
  const deployment::Config config = deployment::load_config(source_dir() + "/config/sim.yaml", nullptr);
  const ChannelNames& ch = config.channels;
  std::ostringstream t;
  t << "\nFloors (target: each stage within 2× of its floor), measured by the bench alone after the "
       "chain's processes were stopped. Render floor: DepthRenderer::render (render, read-back, "
       "conversion) in the bench, the scene tofguard-renderer loads, the run's intrinsics and the last "
       "step's joint path, back to back. Compute: compute_discrepancy on the prepared frames and the model "
       "at their joints. LCM hop floor: a message of the size of "
    << ch.depth << " / " << ch.rendered << " (lcm.image_url), " << ch.discrepancy << " and " << ch.risk
    << " (lcm.url) on a scratch channel at the run's rate, sent → received by the bench's own thread. "
       "Relay floor: the shape of a stage that starts when a process receives a message: the bench "
       "publishes a message of the size of the stage's input, a relay thread of its own publishes one of "
       "the size of its output on receiving it, and the bench's receiver thread receives both; the "
       "second's receive time minus the first's. p50 / p99 / max ms. Stage floors (p50s summed): render "
       "= image hop + render + image hop ("
    << ch.depth << " in, " << ch.rendered << " out); discrepancy = compute + relay (" << ch.rendered << " → "
    << ch.discrepancy << "); risk = relay (" << ch.discrepancy << " → " << ch.risk
    << "; the risk monitor's work not measured).";
  for (const BenchFloors& f : report.floors) {
    if (f.listeners == 0) continue;
    t << " With " << f.listeners
      << " idle LCM instances on each URL while the hops and relays were measured (--floor-listeners), "
         "as the chain's processes are: each message is delivered to every one.";
    break;
  }
  t << "\n\n";
  t << "| arm | size | rate (Hz) | render floor p50 / p99 / max | compute_discrepancy p50 / p99 / max | "
       "LCM hop floor p50 / p99 / max, "
    << ch.depth << " / " << ch.rendered << " | LCM hop floor, " << ch.discrepancy << " | LCM hop floor, "
    << ch.risk << " | relay floor, " << ch.rendered << " → " << ch.discrepancy << " | relay floor, "
    << ch.discrepancy << " → " << ch.risk
    << " | render p50 / floor | discrepancy p50 / floor | risk p50 / floor |\n";
  t << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const BenchFloors& f : report.floors) {
    // The step at the floors' rate: the plain step, or the ramp's first.
    const BenchStep* step = nullptr;
    for (const BenchStep& s : report.steps)
      if (s.arm == f.arm && s.width == f.width && s.height == f.height) step = &s;
    for (const BenchRamp& r : report.ramps)
      if (r.arm == f.arm && r.width == f.width && r.height == f.height && !r.steps.empty())
        step = &r.steps.front();
    const BenchStep none;
    const BenchStep& s = step ? *step : none;
    t << "| " << f.arm << " | " << size_text(f.width, f.height) << " | " << fixed_text(f.rate_hz, 0) << " | "
      << latency_cell(f.render, 2) << " (" << f.render.count << ") | "
      << latency_cell(f.discrepancy_compute, 2) << " (" << f.discrepancy_compute.count << ") | "
      << hop_cell(f.image_hop) << " | " << hop_cell(f.discrepancy_hop) << " | " << hop_cell(f.risk_hop)
      << " | " << relay_cell(f.discrepancy_relay) << " | " << relay_cell(f.risk_relay) << " | "
      << ratio_cell(s.render, render_stage_floor_ms(f)) << " | "
      << ratio_cell(s.discrepancy, discrepancy_stage_floor_ms(f)) << " | "
      << ratio_cell(s.risk, risk_stage_floor_ms(f)) << " |\n";
  }
  return t.str();
}

}  // namespace

double render_stage_floor_ms(const BenchFloors& f) {
  if (f.render.count == 0 || f.image_hop.latency.count == 0) return 0;
  return f.render.p50_ms + 2 * f.image_hop.latency.p50_ms;
}
double discrepancy_stage_floor_ms(const BenchFloors& f) {
  if (f.discrepancy_compute.count == 0 || f.discrepancy_relay.latency.count == 0) return 0;
  return f.discrepancy_compute.p50_ms + f.discrepancy_relay.latency.p50_ms;
}
double risk_stage_floor_ms(const BenchFloors& f) {
  return f.risk_relay.latency.count == 0 ? 0 : f.risk_relay.latency.p50_ms;
}

std::string bench_frames_csv(const BenchReport& report) {
  std::ostringstream csv;
  csv << "arm,width,height,rate_hz,seq,render_ms,discrepancy_ms,compute_ms,risk_ms,end_to_end_ms\n";
  const auto ms = [](const std::optional<double>& v) { return v.value_or(-1.0); };  // -1: none
  const auto add = [&](const BenchStep& step) {
    for (const BenchStep::Frame& f : step.frames)
      csv << step.arm << ',' << step.width << ',' << step.height << ',' << step.rate_hz << ',' << f.seq << ','
          << ms(f.render_ms) << ',' << ms(f.discrepancy_ms) << ',' << ms(f.compute_ms) << ',' << ms(f.risk_ms)
          << ',' << ms(f.end_to_end_ms) << '\n';
  };
  for (const BenchStep& step : report.steps) add(step);
  for (const BenchRamp& ramp : report.ramps)
    for (const BenchStep& step : ramp.steps) add(step);
  return csv.str();
}

std::string bench_markdown(const BenchReport& report) {
  std::ostringstream md;
  md << "tofguard-bench, " << report.date << "; machine: " << report.machine << "\n\n";
  md << "Latencies p50 / p99 / max in ms, each the bench's receive time of the stage's message for the "
        "frame's "
        "seq minus the previous stage's (the first: the time the bench sent the frame); CPU: % of one core "
        "over "
        "the step; dropped: no verdict within 1 s; SAFE: verdicts SAFE (the chain is judging the nominal "
        "frames, not "
        "stopping).\n\n";
  if (!report.steps.empty())
    md << steps_table(report.steps) << compute_lines(report.steps)
       << prediction_lines(report.steps, report.options);
  if (!report.ramps.empty()) {
    md << "| arm | triangles | size | highest rate sustained (Hz) | stopped at |\n";
    md << "| --- | --- | --- | --- | --- |\n";
    std::vector<BenchStep> all;
    for (const BenchRamp& r : report.ramps) {
      md << "| " << r.arm << " | " << r.triangles << " | " << size_text(r.width, r.height) << " | "
         << (r.sustained_hz > 0 ? fixed_text(r.sustained_hz, 0) : std::string("none")) << " | "
         << r.stopped_because << " |\n";
      all.insert(all.end(), r.steps.begin(), r.steps.end());
    }
    md << "\nEvery step of the ramps:\n\n"
       << steps_table(all) << compute_lines(all) << prediction_lines(all, report.options);
  }
  if (!report.floors.empty()) md << floors_table(report);
  for (const std::string& s : report.skipped) md << "\n" << s << "\n";
  return md.str();
}

namespace {

// One curve of a panel: (x, y) points, joined, filled or open circles.
struct Curve {
  std::string label;
  std::vector<std::pair<double, double>> points;
  int colour = 0;
  bool filled = true;
};

// `tick_labels`: the text under an x value (else the value itself).
void draw_panel(cv::Mat* image, const cv::Rect& area, const std::string& title, const std::string& x_label,
                const std::string& y_label, const std::vector<Curve>& curves,
                const std::map<double, std::string>& tick_labels = {}) {
  double x_max = 0, y_max = 0;
  std::vector<double> ticks;
  for (const Curve& c : curves)
    for (const auto& [x, y] : c.points) {
      x_max = std::max(x_max, x);
      y_max = std::max(y_max, y);
      if (std::find(ticks.begin(), ticks.end(), x) == ticks.end()) ticks.push_back(x);
    }
  x_max = x_max > 0 ? 1.08 * x_max : 1;
  y_max = round_axis(y_max > 0 ? y_max : 1, 1e-3);
  const PanelArea panel =
      draw_panel_frame(image, area, PanelStyle{}, title, x_label, y_label, x_max, y_max, ticks, tick_labels);
  for (const Curve& c : curves) {
    std::vector<std::pair<double, double>> points = c.points;
    std::sort(points.begin(), points.end());
    draw_curve(image, panel, points, plot_colour(c.colour), c.filled);
  }
}

}  // namespace

void plot_bench(const BenchReport& report, const std::string& path) {
  // Latency: the plain steps, or each ramp's first (slowest) rate.
  std::vector<BenchStep> steps = report.steps;
  for (const BenchRamp& r : report.ramps)
    if (!r.steps.empty()) steps.push_back(r.steps.front());
  std::vector<std::string> arms;
  for (const BenchStep& s : steps)
    if (std::find(arms.begin(), arms.end(), s.arm) == arms.end()) arms.push_back(s.arm);
  const char* const stage_names[] = {"render", "discrepancy", "risk", "end to end"};
  const int panel_w = 450, panel_h = 420, legend_h = 70;
  const int panels = static_cast<int>(arms.size()) + 1;
  cv::Mat image(panel_h + legend_h, panel_w * panels, CV_8UC3, cv::Scalar(255, 255, 255));
  std::map<double, std::string> size_labels;
  for (const BenchStep& s : steps) size_labels[s.width * s.height / 1000.0] = size_text(s.width, s.height);
  for (size_t a = 0; a < arms.size(); ++a) {
    std::vector<Curve> curves;
    for (int stage = 0; stage < 4; ++stage) {
      for (const bool p99 : {false, true}) {
        Curve c;
        c.colour = stage;
        c.filled = !p99;
        for (const BenchStep& s : steps) {
          if (s.arm != arms[a]) continue;
          const LatencySummary& l = stage == 0   ? s.render
                                    : stage == 1 ? s.discrepancy
                                    : stage == 2 ? s.risk
                                                 : s.end_to_end;
          if (l.count > 0) c.points.push_back({s.width * s.height / 1000.0, p99 ? l.p99_ms : l.p50_ms});
        }
        curves.push_back(c);
      }
    }
    draw_panel(&image, {panel_w * static_cast<int>(a), 0, panel_w, panel_h},
               arms[a] + ": latency per stage (p50 filled, p99 open)", "camera size (kilopixels)", "ms",
               curves, size_labels);
  }
  // Throughput against the scene's triangles, a curve per camera size.
  std::map<std::string, Curve> by_size;
  const auto add_point = [&](int width, int height, size_t triangles, double rate_hz) {
    Curve& c = by_size[size_text(width, height)];
    c.label = size_text(width, height);
    c.points.push_back({static_cast<double>(triangles), rate_hz});
  };
  for (const BenchRamp& r : report.ramps) add_point(r.width, r.height, r.triangles, r.sustained_hz);
  for (const BenchStep& s : report.steps) {
    // Without a ramp: the rate of verdicts delivered (frames not dropped).
    const double delivered = s.frames_sent > 0 ? s.rate_hz * (s.frames_sent - s.frames_dropped) /
                                                     static_cast<double>(s.frames_sent)
                                               : 0;
    add_point(s.width, s.height, s.triangles, delivered);
  }
  std::vector<Curve> throughput;
  int colour = 4;
  for (auto& [size, c] : by_size) {
    c.colour = colour++;
    throughput.push_back(c);
  }
  draw_panel(&image, {panel_w * (panels - 1), 0, panel_w, panel_h},
             report.ramps.empty() ? "rate delivered (no drops)" : "highest rate sustained", "triangles", "Hz",
             throughput);
  for (int stage = 0; stage < 4; ++stage)
    draw_legend_entry(&image, {20 + 150 * stage, panel_h + 20}, 30, 35, plot_colour(stage),
                      stage_names[stage]);
  int i = 0;
  for (const Curve& c : throughput)
    draw_legend_entry(&image, {20 + 150 * i++, panel_h + 50}, 30, 35, plot_colour(c.colour), c.label);
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) fs::create_directories(parent);
  if (!cv::imwrite(path, image)) throw std::runtime_error(path + ": cannot write the plot");
}

}  // namespace tofguard::test
