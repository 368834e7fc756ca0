#pragma once
// Scaffolding the delegate tests share beside their scenes: a scratch directory, and the message a call throws.
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <set>
#include <stdexcept>
#include <string>

namespace test {

/// A fresh directory beside the test executable (so under the build tree), removed with its contents.
struct ScratchDir {
  std::filesystem::path path;
  ScratchDir() {
    namespace fs = std::filesystem;
    static int counter = 0;
    std::error_code ec;
    fs::path base = fs::read_symlink("/proc/self/exe", ec).parent_path();
    if (ec || base.empty()) base = fs::temp_directory_path();
    path = base / ("scratch_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  /// The path of `name` inside the directory.
  std::string operator/(const std::string& name) const { return (path / name).string(); }
  /// The names of the files in the directory.
  std::set<std::string> Files() const {
    std::set<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(path)) names.insert(entry.path().filename().string());
    return names;
  }
};

/// The message of the std::runtime_error that f throws, or "" if it throws nothing.
inline std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace test
