#include "tofguard/spy/spy_process.hpp"

#include <poll.h>

#include <deque>
#include <fstream>
#include <iostream>
#include <regex>

#include <lcm/lcm-cpp.hpp>

#include "tofguard/common/clock.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/spy/message_format.hpp"
#include "tofguard/spy/status_board.hpp"

namespace tofguard::spy {
namespace {

// The last `count` lines of a text file ("" when it cannot be read).
std::string last_lines(const std::string& path, size_t count) {
  std::ifstream in(path);
  std::deque<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    lines.push_back(line);
    if (lines.size() > count) lines.pop_front();
  }
  std::string text;
  for (const auto& line : lines) text += line + "\n";
  return text;
}

struct Receiver {
  bool lines = false;
  std::string footer_file;
  std::vector<std::regex> filters;
  StatusBoard board;
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const int size = static_cast<int>(rbuf->data_size);
    if (lines) {
      if (!filters.empty()) {
        bool match = false;
        for (const auto& f : filters) match = match || std::regex_match(channel, f);
        if (!match) return;
      }
      std::cout << format_message(channel, rbuf->data, size) << std::endl;
    } else {
      board.on_message(channel, rbuf->data, size, monotonic_us(), wall_utime());
    }
  }
};

}  // namespace

ProcessInfo process_info() {
  ProcessInfo info{"tofguard-spy",
                   "Watches the live tofguard channels: a refreshing status board (default: permission to\n"
                   "move and why, latest risk, heartbeats with counters, channel rates, latency from the\n"
                   "camera frame), or --lines: one decoded line per message, filtered by --channel REGEX.\n"
                   "--footer FILE shows the last lines of FILE under the board (e.g. a demo's narration).",
                   /*config_required=*/false};
  info.takes_arguments = true;
  return info;
}

int run_spy(const LcmSettings& lcm_settings, const std::vector<std::string>& args) {
  Receiver receiver;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--lines") {
      receiver.lines = true;
    } else if (args[i] == "--board") {
      receiver.lines = false;
    } else if (args[i] == "--footer" && i + 1 < args.size()) {
      receiver.footer_file = args[++i];
    } else if (args[i] == "--channel" && i + 1 < args.size()) {
      try {
        receiver.filters.emplace_back(args[++i]);
      } catch (const std::regex_error&) {
        std::cerr << "tofguard-spy: --channel: expected a regular expression, got '" << args[i] << "'\n";
        return kConfigErrorExitCode;
      }
    } else {
      std::cerr << "tofguard-spy: unknown argument '" << args[i] << "'\n";
      return kConfigErrorExitCode;
    }
  }
  lcm::LCM safety(lcm_settings.url);
  lcm::LCM images(lcm_settings.image_url);
  if (!safety.good() || !images.good()) {
    std::cerr << "tofguard-spy: cannot open LCM at " << lcm_settings.url << " / " << lcm_settings.image_url
              << "\n";
    return 3;
  }
  safety.subscribe(".*", &Receiver::on_message, &receiver);
  if (lcm_settings.image_url != lcm_settings.url) images.subscribe(".*", &Receiver::on_message, &receiver);
  // LCM 1.3 joins the multicast group lazily, on the first getFileno() or
  // handle(): do it now, so "listening" is true when it is printed.
  safety.getFileno();
  images.getFileno();
  std::cout << "tofguard-spy: listening on " << lcm_settings.url << " and " << lcm_settings.image_url
            << std::endl;

  int64_t next_draw_us = 0;
  while (!stop_requested()) {
    pollfd fds[2] = {{safety.getFileno(), POLLIN, 0}, {images.getFileno(), POLLIN, 0}};
    if (poll(fds, 2, 50) > 0) {
      if (fds[0].revents & POLLIN) safety.handle();
      if (fds[1].revents & POLLIN) images.handle();
    }
    if (!receiver.lines && monotonic_us() >= next_draw_us) {
      next_draw_us = monotonic_us() + 250'000;
      // Clear the screen and draw from the top.
      std::cout << "\033[H\033[2J"
                << "tofguard-spy  " << lcm_settings.url << "  (Ctrl-C to quit)\n\n"
                << receiver.board.render(monotonic_us(), wall_utime());
      if (!receiver.footer_file.empty()) std::cout << "\n" << last_lines(receiver.footer_file, 6);
      std::cout << std::flush;
    }
  }
  return 0;
}

}  // namespace tofguard::spy
