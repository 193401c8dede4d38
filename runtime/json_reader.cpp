#include "runtime/json_reader.h"

#include <cstdlib>
#include <cstring>

namespace plumb::runtime {

const JsonValue* JsonValue::find(const std::string& name) const {
  if (type != Type::kObject) return nullptr;
  for (std::size_t i = 0; i < member_names.size(); ++i) {
    if (member_names[i] == name) return &member_values[i];
  }
  return nullptr;
}

namespace {

// Nesting deeper than this is refused instead of exhausting the stack on hostile input.
constexpr int kMaxDepth = 64;

class Parser {
 public:
  explicit Parser(const std::string& text) : text_(text) {}

  Status parseDocument(JsonValue* out) {
    PLUMB_RETURN_IF_ERROR(parseValue(out, 0));
    skipWhitespace();
    if (pos_ != text_.size()) return error("unexpected text after the JSON value");
    return Status::Ok();
  }

 private:
  Status error(const std::string& what) const {
    int line = 1;
    int column = 1;
    for (std::size_t i = 0; i < pos_ && i < text_.size(); ++i) {
      if (text_[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    return Status::Error("JSON line " + std::to_string(line) + " column " +
                         std::to_string(column) + ": " + what);
  }

  // RFC 8259 whitespace only (not strchr(" \t\r\n", c): that also matches a NUL byte).
  static bool isWhitespace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

  void skipWhitespace() {
    while (pos_ < text_.size() && isWhitespace(text_[pos_])) ++pos_;
  }

  bool consume(char c) {
    skipWhitespace();
    if (pos_ < text_.size() && text_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }

  bool consumeWord(const char* word) {
    const std::size_t n = std::strlen(word);
    if (text_.compare(pos_, n, word) != 0) return false;
    pos_ += n;
    return true;
  }

  Status parseValue(JsonValue* out, int depth) {
    if (depth > kMaxDepth) return error("nesting deeper than " + std::to_string(kMaxDepth));
    skipWhitespace();
    if (pos_ >= text_.size()) return error("unexpected end of text, expected a value");
    const char c = text_[pos_];
    if (c == '{') return parseObject(out, depth);
    if (c == '[') return parseArray(out, depth);
    if (c == '"') {
      out->type = JsonValue::Type::kString;
      return parseString(&out->string);
    }
    if (consumeWord("true")) {
      out->type = JsonValue::Type::kBool;
      out->boolean = true;
      return Status::Ok();
    }
    if (consumeWord("false")) {
      out->type = JsonValue::Type::kBool;
      return Status::Ok();
    }
    if (consumeWord("null")) {
      out->type = JsonValue::Type::kNull;
      return Status::Ok();
    }
    if (c == '-' || (c >= '0' && c <= '9')) return parseNumber(out);
    return error(std::string("unexpected character '") + c + "'");
  }

  Status parseNumber(JsonValue* out) {
    // Validate the JSON number grammar, then let strtod convert the same characters.
    const std::size_t start = pos_;
    auto digits = [&] {
      const std::size_t from = pos_;
      while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') ++pos_;
      return pos_ > from;
    };
    if (text_[pos_] == '-') ++pos_;
    // int = "0" / nonzero digit *digit: "01" is not JSON.
    const std::size_t int_start = pos_;
    if (!digits()) return error("malformed number");
    if (text_[int_start] == '0' && pos_ - int_start > 1) return error("malformed number: leading zero");
    if (pos_ < text_.size() && text_[pos_] == '.') {
      ++pos_;
      if (!digits()) return error("malformed number: digits expected after '.'");
    }
    if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
      ++pos_;
      if (pos_ < text_.size() && (text_[pos_] == '+' || text_[pos_] == '-')) ++pos_;
      if (!digits()) return error("malformed number: digits expected in exponent");
    }
    out->type = JsonValue::Type::kNumber;
    out->number = std::strtod(text_.substr(start, pos_ - start).c_str(), nullptr);
    return Status::Ok();
  }

  static int hexDigit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  }

  static void appendUtf8(unsigned code, std::string* out) {
    if (code < 0x80) {
      out->push_back(static_cast<char>(code));
    } else if (code < 0x800) {
      out->push_back(static_cast<char>(0xC0 | (code >> 6)));
      out->push_back(static_cast<char>(0x80 | (code & 0x3F)));
    } else {
      out->push_back(static_cast<char>(0xE0 | (code >> 12)));
      out->push_back(static_cast<char>(0x80 | ((code >> 6) & 0x3F)));
      out->push_back(static_cast<char>(0x80 | (code & 0x3F)));
    }
  }

  Status parseString(std::string* out) {
    ++pos_;  // opening quote
    out->clear();
    while (pos_ < text_.size()) {
      const char c = text_[pos_++];
      if (c == '"') return Status::Ok();
      if (static_cast<unsigned char>(c) < 0x20) return error("control character inside a string");
      if (c != '\\') {
        out->push_back(c);
        continue;
      }
      if (pos_ >= text_.size()) break;
      const char e = text_[pos_++];
      switch (e) {
        case '"': out->push_back('"'); break;
        case '\\': out->push_back('\\'); break;
        case '/': out->push_back('/'); break;
        case 'b': out->push_back('\b'); break;
        case 'f': out->push_back('\f'); break;
        case 'n': out->push_back('\n'); break;
        case 'r': out->push_back('\r'); break;
        case 't': out->push_back('\t'); break;
        case 'u': {
          if (pos_ + 4 > text_.size()) return error("truncated \\u escape");
          // Exactly four hex digits (strtoul would also take a sign, spaces or "0x").
          unsigned code = 0;
          for (int k = 0; k < 4; ++k) {
            const int digit = hexDigit(text_[pos_ + k]);
            if (digit < 0) return error("malformed \\u escape");
            code = code * 16 + static_cast<unsigned>(digit);
          }
          pos_ += 4;
          appendUtf8(code, out);  // surrogate pairs are kept as two code units; names are ASCII
          break;
        }
        default: return error(std::string("unknown escape \\") + e);
      }
    }
    return error("unterminated string");
  }

  Status parseArray(JsonValue* out, int depth) {
    ++pos_;
    out->type = JsonValue::Type::kArray;
    if (consume(']')) return Status::Ok();
    for (;;) {
      out->items.emplace_back();
      PLUMB_RETURN_IF_ERROR(parseValue(&out->items.back(), depth + 1));
      if (consume(']')) return Status::Ok();
      if (!consume(',')) return error("expected ',' or ']' in array");
    }
  }

  Status parseObject(JsonValue* out, int depth) {
    ++pos_;
    out->type = JsonValue::Type::kObject;
    if (consume('}')) return Status::Ok();
    for (;;) {
      skipWhitespace();
      if (pos_ >= text_.size() || text_[pos_] != '"') return error("expected a member name string");
      out->member_names.emplace_back();
      PLUMB_RETURN_IF_ERROR(parseString(&out->member_names.back()));
      if (!consume(':')) return error("expected ':' after member name");
      out->member_values.emplace_back();
      PLUMB_RETURN_IF_ERROR(parseValue(&out->member_values.back(), depth + 1));
      if (consume('}')) return Status::Ok();
      if (!consume(',')) return error("expected ',' or '}' in object");
    }
  }

  const std::string& text_;
  std::size_t pos_ = 0;
};

}  // namespace

Status parseJson(const std::string& text, JsonValue* out) {
  *out = JsonValue{};
  return Parser(text).parseDocument(out);
}

}  // namespace plumb::runtime
