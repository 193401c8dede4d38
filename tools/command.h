#pragma once
// Subcommand registry of the `plumb` tool. Each tools/cmd_<name>.cpp registers itself with
//   PLUMB_COMMAND(name, "one-line summary", function)
// where function is `int fn(int argc, char** argv)` receiving the arguments after the name.
// main.cpp dispatches; `plumb --help` lists every registered command.
#include <string>
#include <vector>

namespace plumb::tools {

using CommandFn = int (*)(int argc, char** argv);

// Exit codes of every subcommand (docs/DATA_FORMATS.md, "Exit codes").
constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;     // the work failed (bad input data, I/O error); message on stderr
constexpr int kExitUsage = 2;      // the command line is wrong (unknown flag, value out of range)
constexpr int kExitStopped = 3;    // stopped by SIGINT/SIGTERM: outputs are complete up to the stop
constexpr int kExitInternal = 70;  // an internal error or out of memory (EX_SOFTWARE)

struct Command {
  const char* name;
  const char* summary;
  CommandFn fn;
};

std::vector<Command>& commandRegistry();

struct CommandRegistrar {
  CommandRegistrar(const char* name, const char* summary, CommandFn fn) {
    commandRegistry().push_back(Command{name, summary, fn});
  }
};

}  // namespace plumb::tools

#define PLUMB_COMMAND(name, summary, fn) \
  static ::plumb::tools::CommandRegistrar plumb_command_registrar_##name(#name, summary, fn)
