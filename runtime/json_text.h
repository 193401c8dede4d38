#pragma once
// Pieces of JSON text shared by every JSON the project prints (statistics, `plumb eval --json`):
// a string literal with the characters JSON requires escaped, and a number that is `null` when it
// is not finite (JSON has no inf or nan, and a reader must never be handed one).
#include <cmath>
#include <cstdio>
#include <string>

namespace plumb::runtime {

inline std::string jsonString(const std::string& text) {
  std::string out = "\"";
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", c);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

// `format` is a printf format for one double, e.g. "%.6f".
inline std::string jsonNumber(double value, const char* format = "%.6f") {
  if (!std::isfinite(value)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, value);
  return buf;
}

}  // namespace plumb::runtime
