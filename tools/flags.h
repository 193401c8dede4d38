#pragma once
// FlagTable: the one command-line parser of the `plumb` tool. A command declares each flag once,
// with the field it fills, its range and its help line; parse() then checks everything the same way
// for every flag and every command:
//   - unknown, repeated and missing-value flags are usage errors;
//   - an empty value (`--out ""`) is a usage error: it never means "none";
//   - integers are whole decimal numbers within the declared range, parsed in 64 bits and checked
//     BEFORE narrowing (`--output-delay 4294967297` is out of range, never 1);
//   - reals are finite numbers within the declared range.
// Every error names the flag, the value and what was expected, and is reported by the command with
// exit code 2 (kExitUsage). values() lists every flag with its value (given or default): what
// `plumb run --stats` records, so a run can be reproduced from its statistics.
// Adding a flag is one line in the command's table (see runFlagTable in tools/run_parse.cpp).
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "platform/status.h"

namespace plumb::tools {

// A whole decimal number in min..max (usage-error messages name `flag`).
Status parseIntegerValue(const std::string& flag, const std::string& text, long long min, long long max,
                         long long* value);
// A finite real number in min..max.
Status parseRealValue(const std::string& flag, const std::string& text, double min, double max, double* value);

class FlagTable {
 public:
  // A switch (`--no-loops`): *target = true when given.
  FlagTable& toggle(const char* name, bool* target, const char* help);
  // `--name N`, an integer in min..max (the target keeps its default when absent).
  FlagTable& integer(const char* name, const char* value_name, long long min, long long max, long long* target,
                     const char* help);
  // `--name X`, a real number in min..max.
  FlagTable& real(const char* name, const char* value_name, double min, double max, double* target, const char* help);
  // `--name TEXT` (a path, a spec, a name); never empty.
  FlagTable& text(const char* name, const char* value_name, std::string* target, const char* help);
  // A heading line in the usage text.
  FlagTable& section(const char* heading);

  // Parses argv (the arguments after the command name). Positionals go to positional(). --help /
  // -h set help(). The first problem is returned (nothing after it is applied).
  Status parse(int argc, char** argv);
  bool help() const { return help_; }
  bool given(const std::string& name) const;
  const std::vector<std::string>& positional() const { return positional_; }

  // One line (or more) per flag: "  --name VALUE  help", in declaration order.
  std::string usage() const;
  // Every flag with its value as JSON text (strings quoted, switches true/false), declaration order.
  std::vector<std::pair<std::string, std::string>> jsonValues() const;

 private:
  enum class Kind { kToggle, kInteger, kReal, kText, kSection };
  struct Flag {
    std::string name, value_name, help;
    Kind kind = Kind::kToggle;
    long long int_min = 0, int_max = 0;
    double real_min = 0, real_max = 0;
    void* target = nullptr;
    bool given = false;
  };
  Flag& add(Kind kind, const char* name, const char* value_name, void* target, const char* help);
  Flag* find(const std::string& name);
  Status apply(Flag& flag, const std::string& value);

  std::vector<Flag> flags_;
  std::vector<std::string> positional_;
  bool help_ = false;
};

}  // namespace plumb::tools
