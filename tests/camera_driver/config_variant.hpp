#pragma once
// config/sim.yaml with one text replacement, for the camera tests' configs.
#include <string>

#include <gtest/gtest.h>

#include "test_support.hpp"

namespace tofguard::camera_test {

// sim.yaml with the model paths made absolute and `replace` -> `with`
// applied (when `replace` is not empty; it must occur), written to the test
// output folder as <name>.yaml. Returns the path.
inline std::string sim_config_variant(const std::string& name, const std::string& replace = "",
                                      const std::string& with = "") {
  std::string text = test::read_file(test::source_dir() + "/config/sim.yaml");
  const std::string prefix = test::source_dir() + "/config/";
  for (size_t at = 0; (at = text.find("models/", at)) != std::string::npos;
       at += prefix.size() + 7) {
    text.insert(at, prefix);
  }
  if (!replace.empty()) {
    const size_t at = text.find(replace);
    EXPECT_NE(at, std::string::npos) << "sim.yaml no longer contains: " << replace;
    if (at != std::string::npos) text.replace(at, replace.size(), with);
  }
  const std::string path = test::output_dir() + "/" + name + ".yaml";
  test::write_file(path, text);
  return path;
}

}  // namespace tofguard::camera_test
