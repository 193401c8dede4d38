#pragma once
// Shared by the command-line tests: run the built `plumb` tool and capture what it prints, and a
// private scratch folder per test (tests/support/scratch_dir.h).
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/scratch_dir.h"

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

}  // namespace plumb::test
