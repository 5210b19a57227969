#include "tofguard/view/view_compose.hpp"

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cstdio>
#include <type_traits>

#include <opencv2/imgproc.hpp>

#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/common/decode.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/discrepancy/arm_distance.hpp"

namespace tofguard::view {
namespace {

cv::Mat3b depth_panel(const depth_image_t& image, double max_depth_mm, int scale) {
  cv::Mat1b grey(image.height, image.width, uchar(0));
  cv::Mat1b valid(image.height, image.width, uchar(0));
  for (int i = 0; i < image.width * image.height; ++i) {
    const int16_t d = image.depth_mm[i];
    if (d <= 0) continue;
    grey(i / image.width, i % image.width) = cv::saturate_cast<uchar>(255.0 * (1.0 - d / max_depth_mm));
    valid(i / image.width, i % image.width) = 255;
  }
  cv::Mat3b colour;
  cv::applyColorMap(grey, colour, cv::COLORMAP_VIRIDIS);
  colour.setTo(cv::Vec3b(0, 0, 0), valid == 0);
  cv::Mat3b scaled;
  cv::resize(colour, scaled, cv::Size(), scale, scale, cv::INTER_NEAREST);
  return scaled;
}

cv::Mat3b blank_panel(int width, int height, int scale, const std::string& text) {
  cv::Mat3b panel(height * scale, width * scale, cv::Vec3b(40, 40, 40));
  cv::putText(panel, text, cv::Point(8, panel.rows / 2), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return panel;
}

// Outlines the classes of `classes` on the scaled panel: a pixel whose
// right or lower neighbour lies in a lower class is on the outline of its
// own class's field.
void draw_field_outlines(const cv::Mat1b& classes, int scale, cv::Mat3b* panel) {
  const cv::Vec3b colour[3] = {{0, 0, 0}, {0, 220, 255}, {0, 0, 255}};  // BGR: -, yellow, red
  for (int v = 0; v < classes.rows; ++v) {
    for (int u = 0; u < classes.cols; ++u) {
      const uchar c = classes(v, u);
      if (c == 0) continue;
      const bool edge = (u + 1 < classes.cols && classes(v, u + 1) < c) || (u > 0 && classes(v, u - 1) < c) ||
                        (v + 1 < classes.rows && classes(v + 1, u) < c) || (v > 0 && classes(v - 1, u) < c);
      if (edge) (*panel)(cv::Rect(u * scale, v * scale, scale, scale)).setTo(colour[c]);
    }
  }
}

}  // namespace

cv::Mat1b field_classes(const depth_image_t& camera, const link_labels_t& labels, double protective_m,
                        double warning_m) {
  cv::Mat1b classes(camera.height, camera.width, uchar(0));
  const discrepancy::ArmDistance arm(labels);
  if (arm.empty() || labels.width != camera.width || labels.height != camera.height) return classes;
  for (int i = 0; i < camera.width * camera.height; ++i) {
    const int16_t d = camera.depth_mm[i];
    if (d <= 0) continue;
    const double z = d * 1e-3;
    const Eigen::Vector3d point = optical_point_m(camera, i % camera.width, i / camera.width, z);
    const double distance = arm.distance_m(point, warning_m + 0.01);
    classes(i / camera.width, i % camera.width) = distance <= protective_m ? 2
                                                  : distance <= warning_m  ? 1
                                                                           : 0;
  }
  return classes;
}

int panel_scale(int width) { return std::max(1, (320 + width - 1) / width); }

std::string verdict_text(const FrameSet& frames) {
  std::string text = "seq " + std::to_string(frames.camera.seq) + "  ";
  if (!frames.risk) return text + "no verdict";
  const risk_t& r = *frames.risk;
  text += risk_level_name(r.level);
  if (r.cause != risk_t::CAUSE_NONE) text += " " + risk_cause_name(r.cause);
  if (!r.suspect.empty()) text += ", suspect " + r.suspect;
  if (!r.detail.empty()) text += " | " + r.detail;
  return text;
}

std::string user_text(const FrameSet& frames) {
  if (!frames.labels || frames.labels->num_body_regions <= 0 ||
      frames.labels->body_region_separation_m.size() !=
          static_cast<size_t>(frames.labels->num_body_regions)) {
    return "";
  }
  const link_labels_t& l = *frames.labels;
  const auto nearest = std::min_element(l.body_region_separation_m.begin(), l.body_region_separation_m.end());
  char text[160];
  std::snprintf(text, sizeof text, "user: %s nearest, %.2f m",
                l.body_region[nearest - l.body_region_separation_m.begin()].c_str(), *nearest);
  std::string out = text;
  if (frames.limit) {
    const speed_limit_t& limit = *frames.limit;
    std::snprintf(text, sizeof text, " | limit %.2f m/s, set by %s", limit.max_arm_speed_m_s,
                  limit.body_region.empty() ? speed_limit_setter_name(limit.set_by).c_str()
                                            : limit.body_region.c_str());
    out += text;
    if (limit.separation_m >= 0) {
      std::snprintf(text, sizeof text, " at %.2f m", limit.separation_m);
      out += text;
    }
  }
  return out;
}

cv::Mat3b compose_view(const FrameSet& frames, const discrepancy::DiscrepancyOptions& options,
                       double max_depth_mm, double full_scale_mm, const FieldSizes& fields) {
  const int w = frames.camera.width;
  const int h = frames.camera.height;
  const int scale = panel_scale(w);
  cv::Mat3b camera = depth_panel(frames.camera, max_depth_mm, scale);
  if (frames.labels && fields.protective_at_rest_m > 0) {
    // The frame's own S when its verdict gives it, else S at rest.
    const bool from_verdict =
        frames.risk && frames.risk->cause == risk_t::CAUSE_UNKNOWN_OBJECT && frames.risk->threshold > 0;
    const double protective_m = from_verdict ? frames.risk->threshold : fields.protective_at_rest_m;
    const double warning_m = protective_m + fields.warning_margin_m;
    draw_field_outlines(field_classes(frames.camera, *frames.labels, protective_m, warning_m), scale,
                        &camera);
    char legend[96];
    std::snprintf(legend, sizeof legend, "fields: S %.2f m%s, warning %.2f m", protective_m,
                  from_verdict ? "" : " (arm at rest)", warning_m);
    cv::putText(camera, legend, cv::Point(6, camera.rows - 8), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  cv::Mat3b rendered = frames.rendered ? depth_panel(*frames.rendered, max_depth_mm, scale)
                                       : blank_panel(w, h, scale, "no rendered frame");
  cv::Mat3b dis = blank_panel(w, h, scale, "no comparison");
  if (frames.rendered && frames.labels) {
    const auto frame =
        discrepancy::compute_discrepancy(frames.camera, *frames.rendered, *frames.labels, options);
    if (frame.summary.usable) {
      const discrepancy_image_t colour = discrepancy::colour_image(frame, full_scale_mm);
      // RGB on the wire, BGR in OpenCV.
      cv::Mat3b rgb(h, w, reinterpret_cast<cv::Vec3b*>(const_cast<uint8_t*>(colour.rgb.data())));
      cv::Mat3b bgr;
      cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
      cv::resize(bgr, dis, cv::Size(), scale, scale, cv::INTER_NEAREST);
    } else {
      dis = blank_panel(w, h, scale, "unusable: " + frame.summary.unusable_reason.substr(0, 40));
    }
  }
  const std::string user = user_text(frames);
  const int banner = user.empty() ? 28 : 48;
  cv::Mat3b view(banner + camera.rows, 3 * camera.cols, cv::Vec3b(0, 0, 0));
  camera.copyTo(view(cv::Rect(0, banner, camera.cols, camera.rows)));
  rendered.copyTo(view(cv::Rect(camera.cols, banner, camera.cols, camera.rows)));
  dis.copyTo(view(cv::Rect(2 * camera.cols, banner, camera.cols, camera.rows)));
  cv::Scalar colour(200, 200, 200);
  if (frames.risk && frames.risk->level == risk_t::DANGEROUS) colour = cv::Scalar(60, 60, 255);
  if (frames.risk && frames.risk->level == risk_t::WARNING) colour = cv::Scalar(0, 200, 255);
  if (frames.risk && frames.risk->level == risk_t::SAFE) colour = cv::Scalar(80, 220, 80);
  cv::putText(view, verdict_text(frames).substr(0, 110), cv::Point(6, 19), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              colour, 1, cv::LINE_AA);
  if (!user.empty()) {
    cv::putText(view, user.substr(0, 110), cv::Point(6, 39), cv::FONT_HERSHEY_SIMPLEX, 0.5,
                cv::Scalar(230, 230, 230), 1, cv::LINE_AA);
  }
  return view;
}

LogFrames read_log_frames(const std::string& path, const ChannelNames& channels, std::string* error) {
  LogFrames result;
  lcm::LogFile log(path, "r");
  if (!log.good()) {
    *error = path + ": cannot read the LCM log";
    return result;
  }
  std::map<int64_t, depth_image_t> rendered;
  std::map<int64_t, link_labels_t> labels;
  std::map<int64_t, risk_t> risks;
  std::map<int64_t, speed_limit_t> limits;
  // Decodes the event as the type of *message; counts it as skipped if it
  // is not one.
  auto decode = [&](const lcm::LogEvent* event, auto* message) {
    using T = std::remove_pointer_t<decltype(message)>;
    if (auto m = decode_message<T>(event->data, event->datalen)) {
      *message = *m;
      return true;
    }
    result.skipped++;
    return false;
  };
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (event->channel == channels.depth) {
      depth_image_t m;
      if (decode(event, &m) && check_depth_image(m).empty()) result.by_seq[m.seq].camera = m;
    } else if (event->channel == channels.rendered) {
      depth_image_t m;
      if (decode(event, &m) && check_depth_image(m).empty()) rendered[m.seq] = m;
    } else if (event->channel == channels.labels) {
      link_labels_t m;
      if (decode(event, &m) && check_link_labels(m).empty()) labels[m.seq] = m;
    } else if (event->channel == channels.risk) {
      risk_t m;
      if (decode(event, &m) && m.seq >= 0) risks[m.seq] = m;
    } else if (event->channel == channels.speed_limit) {
      speed_limit_t m;
      if (decode(event, &m) && m.seq >= 0 && check_speed_limit(m).empty()) limits[m.seq] = m;
    }
  }
  for (auto& [seq, frames] : result.by_seq) {
    if (auto it = rendered.find(seq); it != rendered.end()) frames.rendered = it->second;
    if (auto it = labels.find(seq); it != labels.end()) frames.labels = it->second;
    if (auto it = risks.find(seq); it != risks.end()) frames.risk = it->second;
    if (auto it = limits.find(seq); it != limits.end()) frames.limit = it->second;
  }
  return result;
}

}  // namespace tofguard::view
