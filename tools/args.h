#pragma once
// Tiny argument reader shared by the subcommands: `--key value`, `--flag`, and positionals.
// Unknown options are an error, so a typo never silently falls back to a default; so is an empty
// value (`--out ""` never means "none"). Numbers go through the one parser of tools/flags.h
// (whole numbers in 64 bits, range-checked before any narrowing). New commands declare their flags
// in a FlagTable (tools/flags.h) instead.
#include <climits>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "tools/flags.h"

namespace plumb::tools {

class Args {
 public:
  // value_options take a value (`--out DIR`); flag_options do not (`--json`).
  Args(int argc, char** argv, std::set<std::string> value_options, std::set<std::string> flag_options) {
    for (int i = 0; i < argc; ++i) {
      std::string a = argv[i];
      if (a == "--help" || a == "-h") { help_ = true; continue; }
      if (a.rfind("--", 0) == 0) {
        std::string key = a.substr(2);
        if (value_options.count(key) || flag_options.count(key)) {
          // A repeated option is a mistake (which one was meant?), not "the last one wins".
          if (values_.count(key) || flags_.count(key)) { error_ = "option --" + key + " given twice"; return; }
        }
        if (value_options.count(key)) {
          if (i + 1 >= argc) { error_ = "option --" + key + " needs a value"; return; }
          if (argv[i + 1][0] == '\0') { error_ = "option --" + key + " needs a value (an empty string is not one)"; return; }
          values_[key] = argv[++i];
        } else if (flag_options.count(key)) {
          flags_.insert(key);
        } else {
          error_ = "unknown option " + a;
          return;
        }
      } else {
        positional_.push_back(a);
      }
    }
  }
  bool help() const { return help_; }
  const std::string& error() const { return error_; }
  bool has(const std::string& key) const { return values_.count(key) || flags_.count(key); }
  std::string get(const std::string& key, const std::string& fallback = "") const {
    auto it = values_.find(key);
    return it == values_.end() ? fallback : it->second;
  }
  // An integer option in min..max (usage error naming the flag otherwise); *value keeps its
  // default when the option is absent.
  Status integer(const std::string& key, long long min, long long max, long long* value) const {
    auto it = values_.find(key);
    return it == values_.end() ? Status::Ok() : parseIntegerValue(key, it->second, min, max, value);
  }
  Status real(const std::string& key, double min, double max, double* value) const {
    auto it = values_.find(key);
    return it == values_.end() ? Status::Ok() : parseRealValue(key, it->second, min, max, value);
  }
  // Older form: sets *ok=false (and leaves fallback) when malformed or beyond a long.
  long getInt(const std::string& key, long fallback, bool* ok) const {
    long long v = fallback;
    if (!integer(key, LONG_MIN, LONG_MAX, &v).ok()) *ok = false;
    return long(v);
  }
  double getDouble(const std::string& key, double fallback, bool* ok) const {
    double v = fallback;
    if (!real(key, -1e308, 1e308, &v).ok()) *ok = false;
    return v;
  }
  const std::vector<std::string>& positional() const { return positional_; }

 private:
  bool help_ = false;
  std::string error_;
  std::map<std::string, std::string> values_;
  std::set<std::string> flags_;
  std::vector<std::string> positional_;
};

}  // namespace plumb::tools
