#pragma once
// Shared by the command-line tests: run the built `plumb` tool and capture what it prints, and a
// private scratch folder per test (ctest runs tests as parallel processes).
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace plumb::test {

inline const std::string kPlumbBinary = PLUMB_BINARY_DIR "/bin/plumb";

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs `plumb <arguments>` through the shell (arguments are passed as written).
inline RunResult runPlumb(const std::string& arguments) {
  RunResult result;
  const std::string command = "'" + kPlumbBinary + "' " + arguments + " 2>&1";
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.output.append(buffer, n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// A fresh folder under the temp directory, removed with everything in it at destruction.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix) {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
    if (::mkdtemp(pattern.data())) path_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  bool ok() const { return !path_.empty(); }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  // Writes `content` to a file in the folder and returns its path.
  std::string write(const std::string& name, const std::string& content) const {
    std::ofstream(file(name), std::ios::binary) << content;
    return file(name);
  }

 private:
  std::string path_;
};

}  // namespace plumb::test
