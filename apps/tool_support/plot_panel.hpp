#pragma once
// The panels of the test tools' PNG plots (tofguard-judge-campaign's
// detection plots, tofguard-bench's latency and throughput plot), drawn
// with OpenCV: title, grid, ticks, axes, curves and legend entries.
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace tofguard::test {

// The i-th curve colour (BGR), eight in turn.
const cv::Scalar& plot_colour(int i);

// An axis's end: `smallest` times 1, 2, 5, 10, 20 ... (starting from a
// power of 10), the first that is at least 1.05 * `value`.
double round_axis(double value, double smallest);

// Where a panel's parts go, in pixels, and the title's size; the plot area
// spans from area.x + 70 to the area's right - 20 and from area.y + top to
// its bottom - 50.
struct PanelStyle {
  int top = 50;
  double title_scale = 0.55;
  int tick_label_dx = -20;  // a tick's label, left of its tick
  int x_label_dx = -60;     // the x axis's label, left of the area's middle
};

// The plot area of a panel: x from 0 to x_max, y from 0 to y_max (higher
// values drawn at y_max).
struct PanelArea {
  int left = 0, right = 0, top = 0, bottom = 0;
  double x_max = 1, y_max = 1;
  cv::Point at(double x, double y) const;
};

// Draws a panel's frame in the rectangle `area` of `image`: the title, five
// grid lines with their values (one decimal when y_max < 10), a tick under
// each of `ticks` labelled with its value (or its text in `tick_labels`),
// the axes and their labels. Returns where the curves go.
PanelArea draw_panel_frame(cv::Mat* image, const cv::Rect& area, const PanelStyle& style,
                           const std::string& title, const std::string& x_label, const std::string& y_label,
                           double x_max, double y_max, const std::vector<double>& ticks,
                           const std::map<double, std::string>& tick_labels = {});

// A curve through `points` in their order: filled circles joined by thick
// lines, or (`filled` false) open circles and thin lines; a NaN y leaves a
// gap.
void draw_curve(cv::Mat* image, const PanelArea& panel, const std::vector<std::pair<double, double>>& points,
                const cv::Scalar& colour, bool filled);

// A legend entry: a line from `at` `line_length` to the right in `colour`,
// `text` starting `text_dx` right of `at`.
void draw_legend_entry(cv::Mat* image, const cv::Point& at, int line_length, int text_dx,
                       const cv::Scalar& colour, const std::string& text);

}  // namespace tofguard::test
