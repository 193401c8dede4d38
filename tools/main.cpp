// plumb: point + line RGB-D odometry. Dispatches to the subcommands registered in cmd_*.cpp.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>

#include "tools/command.h"

namespace plumb::tools {
std::vector<Command>& commandRegistry() {
  static std::vector<Command> registry;
  return registry;
}
}  // namespace plumb::tools

namespace {
void printUsage() {
  auto commands = plumb::tools::commandRegistry();
  std::sort(commands.begin(), commands.end(),
            [](const auto& a, const auto& b) { return std::strcmp(a.name, b.name) < 0; });
  std::printf("usage: plumb <command> [options]\n\ncommands:\n");
  for (const auto& c : commands) std::printf("  %-10s %s\n", c.name, c.summary);
  std::printf("\n`plumb <command> --help` describes a command's options.\n");
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    printUsage();
    return argc < 2 ? 2 : 0;
  }
  for (const auto& c : plumb::tools::commandRegistry()) {
    if (std::strcmp(c.name, argv[1]) != 0) continue;
    // No exception leaves main as an abort: it becomes a message and a documented exit code
    // (docs/DATA_FORMATS.md, "Exit codes"). Outputs are written to temporary files and renamed
    // only when complete, so whatever was interrupted here left no file that looks whole.
    try {
      return c.fn(argc - 2, argv + 2);
    } catch (const std::bad_alloc&) {
      std::fprintf(stderr, "plumb %s: out of memory\n", c.name);
      return plumb::tools::kExitInternal;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "plumb %s: internal error: %s\n", c.name, e.what());
      return plumb::tools::kExitInternal;
    } catch (...) {
      std::fprintf(stderr, "plumb %s: internal error (unknown exception)\n", c.name);
      return plumb::tools::kExitInternal;
    }
  }
  std::fprintf(stderr, "plumb: unknown command '%s' (see plumb --help)\n", argv[1]);
  return 2;
}
