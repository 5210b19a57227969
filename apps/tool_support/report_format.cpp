#include "report_format.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tofguard::test {

std::string fixed_text(double value, int decimals) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(decimals);
  s << value;
  return s.str();
}

double quantile(const std::vector<double>& sorted, double q) {
  const size_t rank = static_cast<size_t>(std::ceil(q * static_cast<double>(sorted.size())));
  return sorted[std::clamp<size_t>(rank, 1, sorted.size()) - 1];
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream s(text);
  for (std::string part; std::getline(s, part, ',');)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

std::vector<double> number_list(const std::string& text) {
  std::vector<double> values;
  for (const std::string& v : split_list(text)) values.push_back(std::stod(v));
  return values;
}

}  // namespace tofguard::test
