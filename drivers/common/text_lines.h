#pragma once
// Line-oriented text files (image lists, trajectories, camera files): every non-blank line split
// into tokens, with its 1-based line number so parse errors can say `file:line: what`.
// Separators are spaces, tabs and commas (the TUM scripts accept all three). `#` starts a
// comment: a whole-line comment is kept (its tokens), a trailing one is dropped.
#include <string>
#include <vector>

#include "platform/status.h"

namespace plumb {

struct TextLine {
  int number = 0;                   // 1-based line number in the file
  bool is_comment = false;          // first non-blank character is '#'
  std::vector<std::string> tokens;  // for comments: the tokens after '#'
};

// Error (naming the file) when it cannot be opened or read. A missing trailing newline is fine.
Status readTextLines(const std::string& path, std::vector<TextLine>* out);

// Strict number parsing: the whole token must be a number ("1.5x" and "" fail). Accepts "nan" and
// "inf" so callers can report them as non-finite rather than as unparsable.
bool parseDouble(const std::string& token, double* value);
bool parseInt(const std::string& token, int* value);

// "path:line" for messages.
std::string fileLine(const std::string& path, int line);

}  // namespace plumb
