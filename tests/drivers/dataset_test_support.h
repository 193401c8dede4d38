#pragma once
// Helpers for the dataset / trajectory / camera tests: a private temporary folder per test (ctest
// runs tests in parallel processes) and small file writers for building bad inputs.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace plumb::testing {

class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "plumb_test_XXXXXX").string();
    if (::mkdtemp(pattern.data())) path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    if (!path_.empty()) std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  std::string file(const std::string& relative) const { return path_ + "/" + relative; }

  // Writes `content` to path()/relative (creating parent folders) and returns the full path.
  std::string write(const std::string& relative, const std::string& content) const {
    const std::string full = file(relative);
    std::filesystem::create_directories(std::filesystem::path(full).parent_path());
    std::ofstream(full, std::ios::binary) << content;
    return full;
  }

 private:
  std::string path_;
};

inline std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The shared TUM data, or "" (the caller skips) when it is absent.
inline std::string sharedDataset(const std::string& name) {
  const std::string dir = std::string(PLUMB_DATASETS_DIR) + "/" + name;
  return std::filesystem::is_directory(dir) ? dir : "";
}

#define PLUMB_SKIP_WITHOUT_DATASET(dir, name)                                         \
  const std::string dir = ::plumb::testing::sharedDataset(name);                      \
  if (dir.empty())                                                                    \
  GTEST_SKIP() << "shared dataset " << name << " not found under " PLUMB_DATASETS_DIR \
               << " (tests that need real TUM data are skipped)"

}  // namespace plumb::testing
