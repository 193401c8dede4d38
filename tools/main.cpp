// plumb: point + line RGB-D odometry. Dispatches to the subcommands registered in cmd_*.cpp.
#include <algorithm>
#include <cstdio>
#include <cstring>

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
    if (!std::strcmp(c.name, argv[1])) return c.fn(argc - 2, argv + 2);
  }
  std::fprintf(stderr, "plumb: unknown command '%s' (see plumb --help)\n", argv[1]);
  return 2;
}
