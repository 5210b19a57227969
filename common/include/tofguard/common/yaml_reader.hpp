#pragma once
// Strict reading of one YAML mapping: every key is looked up by name with
// the type it must have, and finish() rejects keys nobody asked for, so a
// misspelt key is an error instead of a silently ignored setting.
//
// Every error is a ConfigError whose message is one line:
//   <file>:<line>: <dotted.key>: expected <what>, got <what was there>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "tofguard/common/config_error.hpp"

namespace tofguard {

class YamlMap {
 public:
  // `file` is the config's path as given (for messages), `base_dir` the
  // directory relative paths are resolved against, `key_path` the dotted
  // path of this mapping ("" for the document's root).
  YamlMap(YAML::Node node, std::string file, std::string base_dir, std::string key_path);

  bool has(const std::string& key) const;
  // For optional keys: marks `key` as known and says whether it is present.
  bool optional(const std::string& key);

  std::string string(const std::string& key);
  std::optional<std::string> optional_string(const std::string& key);
  // One of `choices`.
  std::string choice(const std::string& key, const std::vector<std::string>& choices);
  bool boolean(const std::string& key);
  int64_t integer(const std::string& key, int64_t min, int64_t max);
  // A finite number in [min, max].
  double number(const std::string& key, double min, double max);
  double optional_number(const std::string& key, double default_value, double min, double max);
  // A duration written in milliseconds (a `..._ms` key) in [min_ms, max_ms],
  // converted here, once, to integer microseconds (llround(ms * 1000)): the
  // monotonic clock is int64 microseconds (clock.hpp), so every deadline
  // check compares integers.
  int64_t milliseconds_as_us(const std::string& key, double min_ms, double max_ms);
  // The same for a duration written in seconds (a `..._s` key).
  int64_t seconds_as_us(const std::string& key, double min_s, double max_s);
  // A sequence of finite numbers; `size` < 0 means any length.
  std::vector<double> numbers(const std::string& key, int size);
  std::vector<std::string> strings(const std::string& key);
  // A path to an existing file (or directory when `directory`), resolved
  // against the config file's directory when relative.
  std::string existing_path(const std::string& key, bool directory = false);
  // A path that need not exist yet, resolved like existing_path.
  std::string path(const std::string& key);
  std::vector<std::string> existing_paths(const std::string& key, bool directory = false);

  YamlMap map(const std::string& key);
  std::optional<YamlMap> optional_map(const std::string& key);
  // A sequence of mappings.
  std::vector<YamlMap> maps(const std::string& key);

  // Every key of this mapping, in file order (for maps keyed by name, such
  // as joints); each is marked as known.
  std::vector<std::string> keys();

  // Throws for every key of this mapping that was not read.
  void finish() const;

  // An error about `key` of this mapping (for checks only the caller can make).
  [[noreturn]] void fail(const std::string& key, const std::string& expected,
                         const std::string& got = "") const;

  const std::string& file() const { return file_; }
  std::string key_path(const std::string& key) const;

 private:
  YAML::Node required_node(const std::string& key, const std::string& expected);
  std::string resolve(const std::string& path) const;

  YAML::Node node_;
  std::string file_;
  std::string base_dir_;
  std::string key_path_;
  std::set<std::string> read_keys_;
};

// Loads a YAML file whose root must be a mapping; errors name the file.
YamlMap load_yaml_file(const std::string& path);

}  // namespace tofguard
