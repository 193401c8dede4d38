#pragma once
// Subcommand registry of the `plumb` tool. Each tools/cmd_<name>.cpp registers itself with
//   PLUMB_COMMAND(name, "one-line summary", function)
// where function is `int fn(int argc, char** argv)` receiving the arguments after the name.
// main.cpp dispatches; `plumb --help` lists every registered command.
#include <string>
#include <vector>

namespace plumb::tools {

using CommandFn = int (*)(int argc, char** argv);

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
