#include "drivers/common/text_lines.h"

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <fstream>

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

Status readTextLines(const std::string& path, std::vector<TextLine>* out) {
  out->clear();
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open (" + std::strerror(errno) + ")");
  std::string text;
  int number = 0;
  while (std::getline(in, text)) {
    ++number;
    std::size_t first = 0;
    while (first < text.size() && isSeparator(text[first])) ++first;
    if (first == text.size()) continue;
    if (text.find('\0') != std::string::npos)
      return Status::Error(fileLine(path, number) + ": binary data in a text file");
    TextLine line;
    line.number = number;
    line.is_comment = text[first] == '#';
    // A `#` after the data starts a trailing comment (`fx 517.3  # Freiburg 1`).
    if (!line.is_comment) text = text.substr(0, text.find('#'));
    splitTokens(text, line.is_comment ? first + 1 : first, &line.tokens);
    out->push_back(std::move(line));
  }
  if (in.bad()) return Status::Error(path + ": read error");
  return Status::Ok();
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
