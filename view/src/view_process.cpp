#include "tofguard/view/view_process.hpp"

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include <lcm/lcm-cpp.hpp>
#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "tofguard/common/clock.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/view/view_compose.hpp"

namespace tofguard::view {
namespace {

int export_log(const ViewSettings& settings, const std::string& log_path, const std::string& out) {
  std::string error;
  const LogFrames frames = read_log_frames(log_path, settings.channels, &error);
  if (!error.empty()) {
    std::cerr << "tofguard-view: " << error << "\n";
    return 1;
  }
  if (frames.by_seq.empty()) {
    std::cerr << "tofguard-view: " << log_path << ": no camera frames on " << settings.channels.depth << "\n";
    return 1;
  }
  const auto options = discrepancy::discrepancy_options(settings.discrepancy);
  const double max_depth_mm = settings.far_m * 1000;
  const double full_scale = settings.discrepancy.colour_image_full_scale_mm;
  const bool video = out.size() > 4 && out.substr(out.size() - 4) == ".mp4";
  cv::VideoWriter writer;
  if (!video) std::filesystem::create_directories(out);
  int written = 0;
  for (const auto& [seq, set] : frames.by_seq) {
    const cv::Mat3b view = compose_view(set, options, max_depth_mm, full_scale, settings.fields);
    if (video) {
      if (!writer.isOpened()) {
        writer.open(out, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), settings.camera_rate_hz, view.size());
        if (!writer.isOpened()) {
          std::cerr << "tofguard-view: cannot write the video " << out << " (OpenCV has no mp4v encoder?)\n";
          return 1;
        }
      }
      writer.write(view);
    } else {
      std::ostringstream name;
      name << out << "/frame_" << std::setw(8) << std::setfill('0') << seq << ".png";
      if (!cv::imwrite(name.str(), view)) {
        std::cerr << "tofguard-view: cannot write " << name.str() << "\n";
        return 1;
      }
    }
    ++written;
  }
  std::cout << "tofguard-view: " << written << " camera frames from " << log_path << " -> " << out
            << (frames.skipped ? " (" + std::to_string(frames.skipped) + " messages did not decode)" : "")
            << std::endl;
  return 0;
}

int live(const ViewSettings& settings) {
  lcm::LCM safety(settings.lcm.url);
  lcm::LCM images(settings.lcm.image_url);
  if (!safety.good() || !images.good()) {
    std::cerr << "tofguard-view: cannot open LCM\n";
    return 3;
  }
  // The newest frames by seq; the view shows the newest complete one.
  std::map<int64_t, FrameSet> pending;
  struct Handler {
    std::map<int64_t, FrameSet>* pending;
    const ViewSettings* settings;
    void depth(const lcm::ReceiveBuffer*, const std::string&, const depth_image_t* m) {
      if (check_depth_image(*m).empty()) (*pending)[m->seq].camera = *m;
    }
    void rendered(const lcm::ReceiveBuffer*, const std::string&, const depth_image_t* m) {
      if (check_depth_image(*m).empty()) (*pending)[m->seq].rendered = *m;
    }
    void labels(const lcm::ReceiveBuffer*, const std::string&, const link_labels_t* m) {
      if (check_link_labels(*m).empty()) (*pending)[m->seq].labels = *m;
    }
    void risk(const lcm::ReceiveBuffer*, const std::string&, const risk_t* m) {
      if (m->seq >= 0) (*pending)[m->seq].risk = *m;
    }
    void limit(const lcm::ReceiveBuffer*, const std::string&, const speed_limit_t* m) {
      if (m->seq >= 0 && check_speed_limit(*m).empty()) (*pending)[m->seq].limit = *m;
    }
  } handler{&pending, &settings};
  images.subscribe(settings.channels.depth, &Handler::depth, &handler);
  images.subscribe(settings.channels.rendered, &Handler::rendered, &handler);
  images.subscribe(settings.channels.labels, &Handler::labels, &handler);
  safety.subscribe(settings.channels.risk, &Handler::risk, &handler);
  safety.subscribe(settings.channels.speed_limit, &Handler::limit, &handler);
  const auto options = discrepancy::discrepancy_options(settings.discrepancy);
  cv::namedWindow("tofguard-view", cv::WINDOW_AUTOSIZE);
  while (!stop_requested()) {
    images.handleTimeout(10);
    while (safety.handleTimeout(0) > 0) {
    }
    // Show the newest frame that has its rendering (or is 300 ms old).
    for (auto it = pending.rbegin(); it != pending.rend(); ++it) {
      const FrameSet& set = it->second;
      if (set.camera.width > 0 && set.rendered && set.labels) {
        cv::imshow("tofguard-view",
                   compose_view(set, options, settings.far_m * 1000,
                                settings.discrepancy.colour_image_full_scale_mm, settings.fields));
        pending.erase(pending.begin(), std::next(it).base());
        break;
      }
    }
    while (pending.size() > 30) pending.erase(pending.begin());
    const int key = cv::waitKey(1);
    if (key == 27 || key == 'q') break;
  }
  return 0;
}

}  // namespace

ProcessInfo process_info() {
  ProcessInfo info{"tofguard-view",
                   "Camera depth, rendered depth and the colour discrepancy image (red: the camera sees\n"
                   "nearer than the model; blue: farther) side by side with the verdict: live in a window,\n"
                   "or with --log FILE --out DIR|FILE.mp4 exported from a log (one PNG per camera frame)."};
  info.takes_arguments = true;
  info.per_camera = true;
  return info;
}

int run_view(const ViewSettings& settings, const std::vector<std::string>& args) {
  std::string log_path, out;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--log" && i + 1 < args.size()) {
      log_path = args[++i];
    } else if (args[i] == "--out" && i + 1 < args.size()) {
      out = args[++i];
    } else {
      std::cerr << "tofguard-view: unknown argument '" << args[i] << "'\n";
      return kConfigErrorExitCode;
    }
  }
  if (log_path.empty() != out.empty()) {
    std::cerr << "tofguard-view: --log FILE and --out DIR|FILE.mp4 go together\n";
    return kConfigErrorExitCode;
  }
  return log_path.empty() ? live(settings) : export_log(settings, log_path, out);
}

}  // namespace tofguard::view
