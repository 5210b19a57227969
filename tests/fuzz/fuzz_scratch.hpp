#pragma once
// A scratch folder for the fuzz targets whose code under test reads files
// (the config loader, the URDF and mesh loaders): made once per process
// under $TMPDIR, removed at exit, so that every input is written to the
// same paths and nothing accumulates.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace tofguard::fuzz {

class Scratch {
 public:
  Scratch() {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern =
        std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/tofguard-fuzz-XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr)
      throw std::runtime_error("cannot make a scratch folder " + pattern);
    folder_ = pattern;
  }
  ~Scratch() {
    std::error_code ec;
    std::filesystem::remove_all(folder_, ec);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;

  const std::filesystem::path& folder() const { return folder_; }

  // Writes `size` bytes to `name` in the folder (replacing it); its path.
  std::string write(const std::string& name, const uint8_t* data, size_t size) const {
    const std::filesystem::path path = folder_ / name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) throw std::runtime_error("cannot write " + path.string());
    return path.string();
  }
  std::string write(const std::string& name, const std::string& text) const {
    return write(name, reinterpret_cast<const uint8_t*>(text.data()), text.size());
  }

 private:
  std::filesystem::path folder_;
};

}  // namespace tofguard::fuzz
