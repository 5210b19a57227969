#pragma once
// Small text and number helpers shared by the test tools' reports
// (tofguard-judge-campaign, tofguard-bench) and their command lines.
#include <string>
#include <vector>

namespace tofguard::test {

// `value` with `decimals` digits after the point ("3.14").
std::string fixed_text(double value, int decimals);

// The value of nearest rank `q` (0..1) of `sorted` (ascending, not empty).
double quantile(const std::vector<double>& sorted, double q);

// The parts of a comma-separated list, empty parts left out ("a,,b": a, b).
std::vector<std::string> split_list(const std::string& text);

// The numbers of a comma-separated list (std::stod each); throws
// std::invalid_argument or std::out_of_range for a part that is not one.
std::vector<double> number_list(const std::string& text);

}  // namespace tofguard::test
