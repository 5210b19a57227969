#include "tofguard/spy/status_board.hpp"

#include <iomanip>
#include <sstream>

#include "tofguard/common/decode.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/speed_limit_t.hpp"
#include "tofguard/spy/message_format.hpp"

namespace tofguard::spy {
namespace {

constexpr int64_t kRateWindowUs = 2'000'000;

std::string age(int64_t us) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(us < 10'000'000 ? 2 : 0) << us * 1e-6 << " s";
  return s.str();
}

}  // namespace

void StatusBoard::on_message(const std::string& channel, const void* data, int size, int64_t now_us,
                             int64_t now_utime) {
  ChannelStats& stats = channels_[channel];
  stats.arrivals_us.push_back(now_us);
  while (!stats.arrivals_us.empty() && now_us - stats.arrivals_us.front() > kRateWindowUs) {
    stats.arrivals_us.pop_front();
  }
  const std::string type = type_of(data, size);
  int64_t camera_utime = 0;
  if (type == "safety_status_t") {
    if (auto m = decode_message<safety_status_t>(data, size)) {
      status_ = m;
      status_arrival_us_ = now_us;
    }
  } else if (type == "risk_t") {
    if (auto m = decode_message<risk_t>(data, size)) {
      on_risk(*m, now_us);
      if (m->seq >= 0) camera_utime = m->utime;
    }
  } else if (type == "speed_limit_t") {
    if (auto m = decode_message<speed_limit_t>(data, size)) {
      limit_ = m;
      limit_arrival_us_ = now_us;
    }
  } else if (type == "heartbeat_t") {
    if (auto m = decode_message<heartbeat_t>(data, size)) heartbeats_[m->process] = {*m, now_us};
  } else if (type == "depth_image_t") {
    if (auto m = decode_message<depth_image_t>(data, size)) {
      camera_utime = m->utime;
      std::deque<int64_t>& arrivals = cameras_[m->camera_id].frame_arrivals_us;
      arrivals.push_back(now_us);
      while (!arrivals.empty() && now_us - arrivals.front() > kRateWindowUs) arrivals.pop_front();
    }
  } else if (type == "link_labels_t") {
    if (auto m = decode_message<link_labels_t>(data, size)) camera_utime = m->utime;
  }
  if (camera_utime > 0) stats.latency_us = now_utime - camera_utime;
}

void StatusBoard::on_risk(const risk_t& risk, int64_t now_us) {
  risk_ = risk;
  risk_arrival_us_ = now_us;
  const auto colon = risk.detail.find(": ");
  if (colon == std::string::npos) return;
  const auto camera = cameras_.find(risk.detail.substr(0, colon));
  if (camera == cameras_.end()) return;
  camera->second.verdict = risk;
  camera->second.verdict_arrival_us = now_us;
}

void StatusBoard::render_cameras(std::ostream& s, int64_t now_us) const {
  s << "CAMERAS (frames over 2 s; the latest verdict naming each):\n";
  if (cameras_.empty()) s << "  no depth frame received\n";
  for (const auto& [id, camera] : cameras_) {
    size_t recent = 0;
    for (int64_t t : camera.frame_arrivals_us) recent += now_us - t <= kRateWindowUs;
    const int64_t frame_age_us =
        camera.frame_arrivals_us.empty() ? 0 : now_us - camera.frame_arrivals_us.back();
    s << "  " << std::left << std::setw(12) << id << std::right << std::fixed << std::setprecision(1)
      << std::setw(6) << recent / (kRateWindowUs * 1e-6) << " Hz, last frame " << age(frame_age_us)
      << (frame_age_us > 200'000 ? " STALE" : "");
    if (camera.verdict) {
      s << ", " << risk_level_name(camera.verdict->level) << " " << age(now_us - camera.verdict_arrival_us)
        << " ago";
      if (camera.verdict->level != risk_t::SAFE) s << ": " << camera.verdict->detail.substr(id.size() + 2);
    }
    s << "\n";
  }
}

std::string StatusBoard::render(int64_t now_us, int64_t) const {
  std::ostringstream s;
  s << "PERMISSION TO MOVE: ";
  if (!status_) {
    s << "NO (no SAFETY_STATUS received)\n";
  } else {
    const int64_t status_age_us = now_us - status_arrival_us_;
    s << (status_->motion_allowed ? "YES" : "NO");
    if (!status_->motion_allowed) {
      s << " (" << stop_name(status_->stop) << (status_->latched ? ", latched" : "") << ", cause "
        << risk_cause_name(status_->cause) << ")";
    }
    s << "  status age " << age(status_age_us) << (status_age_us > 200'000 ? "  STALE" : "") << "\n  "
      << status_->reason << "\n";
  }
  s << "RISK: ";
  if (!risk_) {
    s << "none received\n";
  } else {
    s << risk_level_name(risk_->level) << " " << risk_cause_name(risk_->cause);
    if (!risk_->suspect.empty()) s << ", suspect " << risk_->suspect;
    s << "  (frame seq " << risk_->seq << ", score " << risk_->score << " / threshold " << risk_->threshold
      << ", age " << age(now_us - risk_arrival_us_) << ")\n";
    if (!risk_->detail.empty()) s << "  " << risk_->detail << "\n";
  }
  s << "SPEED LIMIT: ";
  if (!limit_) {
    s << "none received\n";
  } else {
    const int64_t limit_age_us = now_us - limit_arrival_us_;
    s << std::fixed << std::setprecision(2) << limit_->max_arm_speed_m_s << " m/s, set by "
      << speed_limit_setter_name(limit_->set_by);
    if (!limit_->body_region.empty()) s << " (" << limit_->body_region << ")";
    if (limit_->separation_m >= 0) s << " at " << limit_->separation_m << " m";
    s << "  (arm at " << limit_->arm_speed_m_s << " m/s, age " << age(limit_age_us)
      << (limit_age_us > limit_->valid_for_ms * 1000LL ? ", EXPIRED: 0 m/s" : "") << ")\n  " << limit_->reason
      << "\n";
  }
  render_cameras(s, now_us);
  s << "PROCESSES (heartbeats):\n";
  if (heartbeats_.empty()) s << "  none received\n";
  for (const auto& [name, entry] : heartbeats_) {
    const heartbeat_t& hb = entry.first;
    const int64_t hb_age_us = now_us - entry.second;
    s << "  " << std::left << std::setw(22) << name << " age " << std::setw(7) << age(hb_age_us)
      << (hb_age_us > 500'000 ? " MISSING" : "        ") << " in " << hb.frames_in << " out " << hb.frames_out
      << " dropped " << hb.frames_dropped << " decode_err " << hb.decode_errors << " invalid "
      << hb.validation_errors << " | " << hb.status << "\n";
  }
  s << "CHANNELS (rate over 2 s; latency from the camera frame's utime):\n";
  for (const auto& [channel, stats] : channels_) {
    size_t recent = 0;
    for (int64_t t : stats.arrivals_us) recent += now_us - t <= kRateWindowUs;
    s << "  " << std::left << std::setw(22) << channel << std::right << std::fixed << std::setprecision(1)
      << std::setw(7) << recent / (kRateWindowUs * 1e-6) << " Hz";
    if (stats.latency_us) s << "   latency " << std::setprecision(1) << *stats.latency_us / 1000.0 << " ms";
    s << "\n";
  }
  return s.str();
}

}  // namespace tofguard::spy
