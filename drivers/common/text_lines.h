#pragma once
// Line-oriented text files (image lists, trajectories, camera files): every non-blank line split
// into tokens, with its 1-based line number so parse errors can say `file:line: what`.
// Separators are spaces, tabs and commas (the TUM scripts accept all three). `#` starts a
// comment: a whole-line comment is kept (its tokens), a trailing one is dropped.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "platform/input_file.h"
#include "platform/status.h"

namespace plumb {

struct TextLine {
  int number = 0;                   // 1-based line number in the file
  bool is_comment = false;          // first non-blank character is '#'
  std::vector<std::string> tokens;  // for comments: the tokens after '#'
};

// Error (naming the file) when it cannot be opened or read. A missing trailing newline is fine.
// The file is opened and bounded by platform/input_file.h (regular files only, at most
// kMaxTextInputBytes, lines at most kMaxTextLineBytes, a leading UTF-8 byte-order mark skipped).
Status readTextLines(const std::string& path, std::vector<TextLine>* out, uint64_t max_bytes = kMaxTextInputBytes);
// The same lines one at a time: on_line returns false to stop reading (the rest of the file is
// never read), or sets *error to fail. Blank lines are skipped.
Status forEachTextLine(const std::string& path, const std::function<bool(const TextLine&, Status*)>& on_line,
                       uint64_t max_bytes = kMaxTextInputBytes);

// Strict number parsing: the whole token must be a number ("1.5x" and "" fail). Accepts "nan" and
// "inf" so callers can report them as non-finite rather than as unparsable.
bool parseDouble(const std::string& token, double* value);
bool parseInt(const std::string& token, int* value);

// "path:line" for messages.
std::string fileLine(const std::string& path, int line);

}  // namespace plumb
