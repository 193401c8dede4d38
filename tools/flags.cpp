#include "tools/flags.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "runtime/json_text.h"

namespace plumb::tools {
namespace {

std::string realText(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

std::string rangeText(long long min, long long max) { return std::to_string(min) + ".." + std::to_string(max); }

std::string rangeText(double min, double max) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%g..%g", min, max);
  return buffer;
}

}  // namespace

Status parseIntegerValue(const std::string& flag, const std::string& text, long long min, long long max,
                         long long* value) {
  const std::string name = "--" + flag;
  if (text.empty()) return Status::Error(name + " needs a value (an empty string is not one)");
  // Digits only, an optional leading minus: strtoll alone would accept " 5", "+5" and skip spaces.
  const std::size_t first = text[0] == '-' ? 1 : 0;
  bool digits = first < text.size();
  for (std::size_t i = first; i < text.size(); ++i) digits = digits && std::isdigit(static_cast<unsigned char>(text[i]));
  if (!digits) return Status::Error(name + " '" + text + "' is not a whole number (expected " + rangeText(min, max) + ")");
  errno = 0;
  const long long v = std::strtoll(text.c_str(), nullptr, 10);
  if (errno == ERANGE || v < min || v > max) {
    return Status::Error(name + " " + text + " is out of range (expected " + rangeText(min, max) + ")");
  }
  *value = v;
  return Status::Ok();
}

Status parseRealValue(const std::string& flag, const std::string& text, double min, double max, double* value) {
  const std::string name = "--" + flag;
  if (text.empty()) return Status::Error(name + " needs a value (an empty string is not one)");
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || std::isspace(static_cast<unsigned char>(text[0]))) {
    return Status::Error(name + " '" + text + "' is not a number (expected " + rangeText(min, max) + ")");
  }
  if (!std::isfinite(v) || errno == ERANGE || v < min || v > max) {
    return Status::Error(name + " " + text + " is out of range (expected " + rangeText(min, max) + ")");
  }
  *value = v;
  return Status::Ok();
}

FlagTable::Flag& FlagTable::add(Kind kind, const char* name, const char* value_name, void* target, const char* help) {
  Flag f;
  f.kind = kind, f.name = name, f.value_name = value_name, f.target = target, f.help = help;
  flags_.push_back(f);
  return flags_.back();
}

FlagTable& FlagTable::toggle(const char* name, bool* target, const char* help) {
  add(Kind::kToggle, name, "", target, help);
  return *this;
}

FlagTable& FlagTable::integer(const char* name, const char* value_name, long long min, long long max, long long* target,
                              const char* help) {
  Flag& f = add(Kind::kInteger, name, value_name, target, help);
  f.int_min = min, f.int_max = max;
  return *this;
}

FlagTable& FlagTable::real(const char* name, const char* value_name, double min, double max, double* target,
                           const char* help) {
  Flag& f = add(Kind::kReal, name, value_name, target, help);
  f.real_min = min, f.real_max = max;
  return *this;
}

FlagTable& FlagTable::text(const char* name, const char* value_name, std::string* target, const char* help) {
  add(Kind::kText, name, value_name, target, help);
  return *this;
}

FlagTable& FlagTable::section(const char* heading) {
  add(Kind::kSection, "", "", nullptr, heading);
  return *this;
}

FlagTable::Flag* FlagTable::find(const std::string& name) {
  for (Flag& f : flags_) {
    if (f.kind != Kind::kSection && f.name == name) return &f;
  }
  return nullptr;
}

bool FlagTable::given(const std::string& name) const {
  for (const Flag& f : flags_) {
    if (f.kind != Kind::kSection && f.name == name) return f.given;
  }
  return false;
}

Status FlagTable::apply(Flag& f, const std::string& value) {
  switch (f.kind) {
    case Kind::kInteger:
      return parseIntegerValue(f.name, value, f.int_min, f.int_max, static_cast<long long*>(f.target));
    case Kind::kReal:
      return parseRealValue(f.name, value, f.real_min, f.real_max, static_cast<double*>(f.target));
    case Kind::kText:
      if (value.empty()) return Status::Error("--" + f.name + " needs a value (an empty string is not one)");
      *static_cast<std::string*>(f.target) = value;
      return Status::Ok();
    default:
      return Status::Ok();
  }
}

Status FlagTable::parse(int argc, char** argv) {
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      help_ = true;
      continue;
    }
    if (a.rfind("--", 0) != 0 || a.size() == 2) {
      positional_.push_back(a);
      continue;
    }
    Flag* f = find(a.substr(2));
    if (f == nullptr) return Status::Error("unknown option " + a);
    // A repeated option is a mistake (which one was meant?), not "the last one wins".
    if (f->given) return Status::Error("option " + a + " given twice");
    f->given = true;
    if (f->kind == Kind::kToggle) {
      *static_cast<bool*>(f->target) = true;
      continue;
    }
    if (i + 1 >= argc) return Status::Error("option " + a + " needs a value");
    PLUMB_RETURN_IF_ERROR(apply(*f, argv[++i]));
  }
  return Status::Ok();
}

std::string FlagTable::usage() const {
  std::string out;
  for (const Flag& f : flags_) {
    if (f.kind == Kind::kSection) {
      out += std::string(f.help) + "\n";
      continue;
    }
    std::string head = "  --" + f.name + (f.value_name.empty() ? "" : " " + f.value_name);
    if (head.size() < 23) head.resize(23, ' ');
    else head += "\n" + std::string(23, ' ');
    // Continuation lines of the help text line up under its first line.
    std::string help;
    for (char c : f.help) {
      help += c;
      if (c == '\n') help += std::string(23, ' ');
    }
    out += head + help + "\n";
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> FlagTable::jsonValues() const {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Flag& f : flags_) {
    switch (f.kind) {
      case Kind::kToggle: out.emplace_back(f.name, *static_cast<const bool*>(f.target) ? "true" : "false"); break;
      case Kind::kInteger: out.emplace_back(f.name, std::to_string(*static_cast<const long long*>(f.target))); break;
      case Kind::kReal: out.emplace_back(f.name, realText(*static_cast<const double*>(f.target))); break;
      case Kind::kText: {
        const std::string& v = *static_cast<const std::string*>(f.target);
        out.emplace_back(f.name, v.empty() ? "null" : runtime::jsonString(v));
        break;
      }
      case Kind::kSection: break;
    }
  }
  return out;
}

}  // namespace plumb::tools
