#include "tofguard/common/yaml_reader.hpp"

#include <cmath>
#include <filesystem>
#include <sstream>

namespace tofguard {
namespace {

std::string describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsMap()) return "a mapping";
  if (node.IsSequence()) return "a list";
  return "'" + node.Scalar() + "'";
}

std::string location(const std::string& file, const YAML::Node& node) {
  if (node.IsDefined() && node.Mark().line >= 0) {
    return file + ":" + std::to_string(node.Mark().line + 1);
  }
  return file;
}

bool parse_number(const YAML::Node& node, double* out) {
  if (!node.IsScalar()) return false;
  try {
    *out = node.as<double>();
  } catch (const YAML::Exception&) {
    return false;
  }
  return std::isfinite(*out);
}

}  // namespace

YamlMap::YamlMap(YAML::Node node, std::string file, std::string base_dir, std::string key_path)
    : node_(std::move(node)),
      file_(std::move(file)),
      base_dir_(std::move(base_dir)),
      key_path_(std::move(key_path)) {}

std::string YamlMap::key_path(const std::string& key) const {
  return key_path_.empty() ? key : key_path_ + "." + key;
}

void YamlMap::fail(const std::string& key, const std::string& expected, const std::string& got) const {
  YAML::Node at = node_[key];
  std::string message =
      location(file_, at.IsDefined() ? at : node_) + ": " + key_path(key) + ": expected " + expected;
  if (!got.empty()) message += ", got " + got;
  throw ConfigError(message);
}

bool YamlMap::has(const std::string& key) const { return node_[key].IsDefined() && !node_[key].IsNull(); }

bool YamlMap::optional(const std::string& key) {
  read_keys_.insert(key);
  return has(key);
}

YAML::Node YamlMap::required_node(const std::string& key, const std::string& expected) {
  read_keys_.insert(key);
  const YAML::Node& node = node_;  // const lookup: never inserts the key
  YAML::Node value = node[key];
  if (!value.IsDefined() || value.IsNull()) {
    throw ConfigError(location(file_, node_) + ": " + key_path(key) + ": missing key, expected " + expected);
  }
  return value;
}

std::string YamlMap::string(const std::string& key) {
  const std::string expected = "a string";
  YAML::Node value = required_node(key, expected);
  if (!value.IsScalar() || value.Scalar().empty()) fail(key, "a non-empty string", describe(value));
  return value.Scalar();
}

std::optional<std::string> YamlMap::optional_string(const std::string& key) {
  if (!optional(key)) return std::nullopt;
  return string(key);
}

std::string YamlMap::choice(const std::string& key, const std::vector<std::string>& choices) {
  std::string expected = "one of";
  for (size_t i = 0; i < choices.size(); ++i) expected += (i ? ", " : " ") + choices[i];
  YAML::Node value = required_node(key, expected);
  if (value.IsScalar()) {
    for (const auto& c : choices) {
      if (value.Scalar() == c) return c;
    }
  }
  fail(key, expected, describe(value));
}

bool YamlMap::boolean(const std::string& key) {
  YAML::Node value = required_node(key, "true or false");
  if (value.IsScalar()) {
    const std::string& s = value.Scalar();
    if (s == "true") return true;
    if (s == "false") return false;
  }
  fail(key, "true or false", describe(value));
}

int64_t YamlMap::integer(const std::string& key, int64_t min, int64_t max) {
  std::ostringstream expected;
  expected << "an integer in [" << min << ", " << max << "]";
  YAML::Node value = required_node(key, expected.str());
  int64_t result = 0;
  bool ok = value.IsScalar();
  if (ok) {
    try {
      result = value.as<int64_t>();
    } catch (const YAML::Exception&) {
      ok = false;
    }
  }
  if (!ok || result < min || result > max) fail(key, expected.str(), describe(value));
  return result;
}

double YamlMap::number(const std::string& key, double min, double max) {
  std::ostringstream expected;
  expected << "a number in [" << min << ", " << max << "]";
  YAML::Node value = required_node(key, expected.str());
  double result = 0;
  if (!parse_number(value, &result) || result < min || result > max) {
    fail(key, expected.str(), describe(value));
  }
  return result;
}

int64_t YamlMap::milliseconds_as_us(const std::string& key, double min_ms, double max_ms) {
  return static_cast<int64_t>(std::llround(number(key, min_ms, max_ms) * 1000.0));
}

int64_t YamlMap::seconds_as_us(const std::string& key, double min_s, double max_s) {
  return static_cast<int64_t>(std::llround(number(key, min_s, max_s) * 1e6));
}

double YamlMap::optional_number(const std::string& key, double default_value, double min, double max) {
  if (!optional(key)) return default_value;
  return number(key, min, max);
}

std::vector<double> YamlMap::numbers(const std::string& key, int size) {
  const std::string expected =
      size < 0 ? std::string("a list of numbers") : "a list of " + std::to_string(size) + " numbers";
  YAML::Node value = required_node(key, expected);
  if (!value.IsSequence() || (size >= 0 && static_cast<int>(value.size()) != size)) {
    fail(key, expected, value.IsSequence() ? std::to_string(value.size()) + " entries" : describe(value));
  }
  std::vector<double> result;
  for (const auto& item : value) {
    double x = 0;
    if (!parse_number(item, &x)) fail(key, expected, "the entry " + describe(item));
    result.push_back(x);
  }
  return result;
}

std::vector<std::string> YamlMap::strings(const std::string& key) {
  YAML::Node value = required_node(key, "a list of strings");
  if (!value.IsSequence()) fail(key, "a list of strings", describe(value));
  std::vector<std::string> result;
  for (const auto& item : value) {
    if (!item.IsScalar() || item.Scalar().empty()) {
      fail(key, "a list of strings", "the entry " + describe(item));
    }
    result.push_back(item.Scalar());
  }
  return result;
}

std::string YamlMap::resolve(const std::string& path) const {
  std::filesystem::path p(path);
  if (p.is_relative()) p = std::filesystem::path(base_dir_) / p;
  return p.lexically_normal().string();
}

std::string YamlMap::existing_path(const std::string& key, bool directory) {
  const std::string given = string(key);
  const std::string resolved = resolve(given);
  std::error_code ec;
  const bool ok = directory ? std::filesystem::is_directory(resolved, ec)
                            : std::filesystem::is_regular_file(resolved, ec);
  if (!ok) {
    fail(key, directory ? "an existing directory" : "an existing file",
         "'" + given + "' (" + resolved + " does not exist)");
  }
  return resolved;
}

std::string YamlMap::path(const std::string& key) { return resolve(string(key)); }

std::vector<std::string> YamlMap::existing_paths(const std::string& key, bool directory) {
  std::vector<std::string> result;
  for (const auto& given : strings(key)) {
    const std::string resolved = resolve(given);
    std::error_code ec;
    const bool ok = directory ? std::filesystem::is_directory(resolved, ec)
                              : std::filesystem::is_regular_file(resolved, ec);
    if (!ok) {
      fail(key, directory ? "existing directories" : "existing files",
           "'" + given + "' (" + resolved + " does not exist)");
    }
    result.push_back(resolved);
  }
  return result;
}

YamlMap YamlMap::map(const std::string& key) {
  YAML::Node value = required_node(key, "a mapping");
  if (!value.IsMap()) fail(key, "a mapping", describe(value));
  return YamlMap(value, file_, base_dir_, key_path(key));
}

std::optional<YamlMap> YamlMap::optional_map(const std::string& key) {
  if (!optional(key)) return std::nullopt;
  return map(key);
}

std::vector<YamlMap> YamlMap::maps(const std::string& key) {
  YAML::Node value = required_node(key, "a list of mappings");
  if (!value.IsSequence()) fail(key, "a list of mappings", describe(value));
  std::vector<YamlMap> result;
  for (size_t i = 0; i < value.size(); ++i) {
    if (!value[i].IsMap()) fail(key, "a list of mappings", "the entry " + describe(value[i]));
    result.emplace_back(value[i], file_, base_dir_, key_path(key) + "[" + std::to_string(i) + "]");
  }
  return result;
}

std::vector<std::string> YamlMap::keys() {
  std::vector<std::string> result;
  for (const auto& entry : node_) {
    result.push_back(entry.first.Scalar());
    read_keys_.insert(result.back());
  }
  return result;
}

void YamlMap::finish() const {
  std::set<std::string> seen;
  for (const auto& entry : node_) {
    const std::string key = entry.first.Scalar();
    // yaml-cpp keeps both entries of a duplicated key and lookups see only
    // the first: a silently ignored setting, so it is an error.
    if (!seen.insert(key).second) {
      throw ConfigError(location(file_, entry.first) + ": " + key_path(key) +
                        ": duplicate key, expected each key once");
    }
    if (read_keys_.count(key) == 0) {
      std::string known;
      for (const auto& k : read_keys_) known += (known.empty() ? "" : ", ") + k;
      throw ConfigError(location(file_, entry.first) + ": " + key_path(key) +
                        ": unknown key, expected one of: " + known);
    }
  }
}

YamlMap load_yaml_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw ConfigError(path + ": cannot read the config file: no such file");
  }
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(path + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw ConfigError(path + ": cannot read the config file: " + e.what());
  }
  if (!root.IsMap()) {
    throw ConfigError(path + ": expected a YAML mapping at the top, got " + describe(root));
  }
  const std::string base_dir = std::filesystem::absolute(path).parent_path().lexically_normal().string();
  return YamlMap(root, path, base_dir, "");
}

}  // namespace tofguard
