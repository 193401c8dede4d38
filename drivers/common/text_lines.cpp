#include "drivers/common/text_lines.h"

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

#include "platform/input_file.h"

namespace plumb {
namespace {

bool isSeparator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; }

void splitTokens(const std::string& text, std::size_t begin, std::vector<std::string>* tokens) {
  std::size_t i = begin;
  while (i < text.size()) {
    while (i < text.size() && isSeparator(text[i])) ++i;
    std::size_t start = i;
    while (i < text.size() && !isSeparator(text[i])) ++i;
    if (i > start) tokens->push_back(text.substr(start, i - start));
  }
}

}  // namespace

Status forEachTextLine(const std::string& path, const std::function<bool(const TextLine&, Status*)>& on_line,
                       uint64_t max_bytes) {
  // Bounded, streamed, non-blocking open (platform/input_file.h): /dev/zero, a FIFO or a
  // gigabyte of one line fails at once in bounded memory instead of being read whole.
  TextLine line;
  return forEachInputLine(path, max_bytes, "", [&](int number, const std::string& text, Status* error) {
    std::size_t first = 0;
    while (first < text.size() && isSeparator(text[first])) ++first;
    if (first == text.size()) return true;
    line.number = number;
    line.is_comment = text[first] == '#';
    line.tokens.clear();
    // A `#` after the data starts a trailing comment (`fx 517.3  # Freiburg 1`).
    if (line.is_comment) {
      splitTokens(text, first + 1, &line.tokens);
    } else {
      splitTokens(text.substr(0, text.find('#')), first, &line.tokens);
    }
    return on_line(line, error);
  });
}

Status readTextLines(const std::string& path, std::vector<TextLine>* out, uint64_t max_bytes) {
  out->clear();
  return forEachTextLine(
      path,
      [out](const TextLine& line, Status*) {
        out->push_back(line);
        return true;
      },
      max_bytes);
}

bool parseDouble(const std::string& token, double* value) {
  if (token.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(token.c_str(), &end);
  if (end != token.c_str() + token.size()) return false;
  *value = v;
  return true;
}

bool parseInt(const std::string& token, int* value) {
  if (token.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(token.c_str(), &end, 10);
  if (end != token.c_str() + token.size() || errno == ERANGE || v < INT_MIN || v > INT_MAX) return false;
  *value = static_cast<int>(v);
  return true;
}

std::string fileLine(const std::string& path, int line) { return path + ":" + std::to_string(line); }

}  // namespace plumb
