#include "plot_panel.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "report_format.hpp"

namespace tofguard::test {

const cv::Scalar& plot_colour(int i) {
  static const cv::Scalar colours[] = {{200, 60, 30}, {30, 120, 220}, {40, 160, 40}, {160, 40, 160},
                                       {0, 160, 200}, {90, 90, 90},   {220, 140, 0}, {120, 60, 0}};
  return colours[i % 8];
}

double round_axis(double value, double smallest) {
  double axis = smallest;
  while (axis < 1.05 * value) axis *= (std::to_string(axis / smallest).substr(0, 1) == "2") ? 2.5 : 2;
  return axis;
}

cv::Point PanelArea::at(double x, double y) const {
  return cv::Point(left + static_cast<int>((right - left) * x / x_max),
                   bottom - static_cast<int>((bottom - top) * std::min(y, y_max) / y_max));
}

PanelArea draw_panel_frame(cv::Mat* image, const cv::Rect& area, const PanelStyle& style,
                           const std::string& title, const std::string& x_label, const std::string& y_label,
                           double x_max, double y_max, const std::vector<double>& ticks,
                           const std::map<double, std::string>& tick_labels) {
  const cv::Scalar black(0, 0, 0), grey(200, 200, 200);
  PanelArea p;
  p.left = area.x + 70;
  p.right = area.x + area.width - 20;
  p.top = area.y + style.top;
  p.bottom = area.y + area.height - 50;
  p.x_max = x_max;
  p.y_max = y_max;
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(*image, title, {area.x + 10, area.y + 25}, font, style.title_scale, black, 1, cv::LINE_AA);
  for (int i = 0; i <= 4; ++i) {
    const double y = y_max * i / 4;
    cv::line(*image, p.at(0, y), p.at(x_max, y), grey, 1);
    cv::putText(*image, fixed_text(y, y_max < 10 ? 1 : 0), {area.x + 5, p.at(0, y).y + 5}, font, 0.4, black,
                1, cv::LINE_AA);
  }
  for (double x : ticks) {
    cv::line(*image, p.at(x, 0), p.at(x, 0) + cv::Point(0, 5), black, 1);
    std::ostringstream l;
    l << x;
    const auto label = tick_labels.find(x);
    cv::putText(*image, label == tick_labels.end() ? l.str() : label->second,
                p.at(x, 0) + cv::Point(style.tick_label_dx, 20), font, 0.4, black, 1, cv::LINE_AA);
  }
  cv::line(*image, p.at(0, 0), p.at(x_max, 0), black, 1);
  cv::line(*image, p.at(0, 0), p.at(0, y_max), black, 1);
  cv::putText(*image, x_label, {(p.left + p.right) / 2 + style.x_label_dx, p.bottom + 40}, font, 0.45, black,
              1, cv::LINE_AA);
  cv::putText(*image, y_label, {area.x + 5, p.top - 10}, font, 0.45, black, 1, cv::LINE_AA);
  return p;
}

void draw_curve(cv::Mat* image, const PanelArea& panel, const std::vector<std::pair<double, double>>& points,
                const cv::Scalar& colour, bool filled) {
  std::optional<cv::Point> previous;
  for (const auto& [x, y] : points) {
    if (std::isnan(y)) {
      previous.reset();
      continue;
    }
    const cv::Point here = panel.at(x, y);
    cv::circle(*image, here, filled ? 4 : 3, colour, filled ? cv::FILLED : 1, cv::LINE_AA);
    if (previous) cv::line(*image, *previous, here, colour, filled ? 2 : 1, cv::LINE_AA);
    previous = here;
  }
}

void draw_legend_entry(cv::Mat* image, const cv::Point& at, int line_length, int text_dx,
                       const cv::Scalar& colour, const std::string& text) {
  cv::line(*image, at, at + cv::Point(line_length, 0), colour, 2, cv::LINE_AA);
  cv::putText(*image, text, at + cv::Point(text_dx, 5), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0),
              1, cv::LINE_AA);
}

}  // namespace tofguard::test
