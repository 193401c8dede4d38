// libFuzzer target for the JSON reader (runtime/json_reader.h). Beyond "no crash":
//  - differential: parseJson accepts a text exactly when an independent RFC 8259 grammar check
//    (below, written from the RFC's ABNF) accepts it and no value is nested deeper than the
//    reader's documented limit (64);
//  - round trip: an accepted tree printed back as JSON parses to the same tree (numbers bit for
//    bit; values beyond double range, read as +-inf, print as +-1e999);
//  - JsonValue::find returns the first member of that name.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "fuzz/fuzz_support.h"
#include "runtime/json_reader.h"

namespace {

using plumb::runtime::JsonValue;

constexpr int kReaderMaxDepth = 64;  // runtime/json_reader.cpp: kMaxDepth

// RFC 8259 grammar, recursive descent over the ABNF; tracks the deepest value's nesting level.
class GrammarCheck {
 public:
  explicit GrammarCheck(const std::string& text) : s_(text) {}
  // True when the whole text is one JSON value surrounded by whitespace.
  bool document() {
    ws();
    if (!value(0)) return false;
    ws();
    return i_ == s_.size();
  }
  int deepest() const { return deepest_; }

 private:
  bool at(char c) const { return i_ < s_.size() && s_[i_] == c; }
  bool digit() const { return i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9'; }
  void ws() {
    while (at(' ') || at('\t') || at('\n') || at('\r')) ++i_;
  }
  bool literal(const char* word) {
    const std::size_t n = std::strlen(word);
    if (s_.compare(i_, n, word) != 0) return false;
    i_ += n;
    return true;
  }
  bool value(int depth) {
    if (depth > 1000) return false;  // the fuzzer's own stack guard; far beyond the reader's limit
    if (depth > deepest_) deepest_ = depth;
    if (at('{')) return object(depth);
    if (at('[')) return array(depth);
    if (at('"')) return string();
    if (at('-') || digit()) return number();
    return literal("true") || literal("false") || literal("null");
  }
  bool number() {
    if (at('-')) ++i_;
    if (at('0')) {
      ++i_;
    } else if (digit()) {
      while (digit()) ++i_;
    } else {
      return false;
    }
    if (at('.')) {
      ++i_;
      if (!digit()) return false;
      while (digit()) ++i_;
    }
    if (at('e') || at('E')) {
      ++i_;
      if (at('+') || at('-')) ++i_;
      if (!digit()) return false;
      while (digit()) ++i_;
    }
    return true;
  }
  static bool hex(char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F'); }
  bool string() {
    ++i_;
    while (i_ < s_.size()) {
      const unsigned char c = static_cast<unsigned char>(s_[i_++]);
      if (c == '"') return true;
      if (c < 0x20) return false;
      if (c != '\\') continue;
      if (i_ >= s_.size()) return false;
      const char e = s_[i_++];
      if (std::strchr("\"\\/bfnrt", e) != nullptr && e != '\0') continue;
      if (e != 'u' || i_ + 4 > s_.size()) return false;
      for (int k = 0; k < 4; ++k)
        if (!hex(s_[i_++])) return false;
    }
    return false;
  }
  bool array(int depth) {
    ++i_;
    ws();
    if (at(']')) return ++i_, true;
    for (;;) {
      ws();
      if (!value(depth + 1)) return false;
      ws();
      if (at(']')) return ++i_, true;
      if (!at(',')) return false;
      ++i_;
    }
  }
  bool object(int depth) {
    ++i_;
    ws();
    if (at('}')) return ++i_, true;
    for (;;) {
      ws();
      if (!at('"') || !string()) return false;
      ws();
      if (!at(':')) return false;
      ++i_;
      ws();
      if (!value(depth + 1)) return false;
      ws();
      if (at('}')) return ++i_, true;
      if (!at(',')) return false;
      ++i_;
    }
  }

  const std::string& s_;
  std::size_t i_ = 0;
  int deepest_ = 0;
};

void printString(const std::string& s, std::string* out) {
  out->push_back('"');
  for (const char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out->push_back('\\');
      out->push_back(ch);
    } else if (c < 0x20) {
      char escape[8];
      std::snprintf(escape, sizeof(escape), "\\u%04x", c);
      *out += escape;
    } else {
      out->push_back(ch);
    }
  }
  out->push_back('"');
}

void print(const JsonValue& v, std::string* out) {
  switch (v.type) {
    case JsonValue::Type::kNull: *out += "null"; return;
    case JsonValue::Type::kBool: *out += v.boolean ? "true" : "false"; return;
    case JsonValue::Type::kNumber: {
      if (std::isinf(v.number)) {
        *out += v.number > 0 ? "1e999" : "-1e999";
        return;
      }
      FUZZ_CHECK(!std::isnan(v.number));  // the grammar has no NaN
      char text[40];
      std::snprintf(text, sizeof(text), "%.17g", v.number);
      *out += text;
      return;
    }
    case JsonValue::Type::kString: printString(v.string, out); return;
    case JsonValue::Type::kArray:
      out->push_back('[');
      for (std::size_t i = 0; i < v.items.size(); ++i) {
        if (i > 0) out->push_back(',');
        print(v.items[i], out);
      }
      out->push_back(']');
      return;
    case JsonValue::Type::kObject:
      FUZZ_CHECK(v.member_names.size() == v.member_values.size());
      out->push_back('{');
      for (std::size_t i = 0; i < v.member_names.size(); ++i) {
        if (i > 0) out->push_back(',');
        printString(v.member_names[i], out);
        out->push_back(':');
        print(v.member_values[i], out);
      }
      out->push_back('}');
      return;
  }
}

bool same(const JsonValue& a, const JsonValue& b) {
  if (a.type != b.type) return false;
  switch (a.type) {
    case JsonValue::Type::kNull: return true;
    case JsonValue::Type::kBool: return a.boolean == b.boolean;
    case JsonValue::Type::kNumber: return std::memcmp(&a.number, &b.number, sizeof(double)) == 0;
    case JsonValue::Type::kString: return a.string == b.string;
    case JsonValue::Type::kArray:
      if (a.items.size() != b.items.size()) return false;
      for (std::size_t i = 0; i < a.items.size(); ++i)
        if (!same(a.items[i], b.items[i])) return false;
      return true;
    case JsonValue::Type::kObject:
      if (a.member_names != b.member_names || a.member_values.size() != b.member_values.size()) return false;
      for (std::size_t i = 0; i < a.member_values.size(); ++i)
        if (!same(a.member_values[i], b.member_values[i])) return false;
      return true;
  }
  return false;
}

void checkFind(const JsonValue& v) {
  for (const JsonValue& item : v.items) checkFind(item);
  for (std::size_t i = 0; i < v.member_names.size(); ++i) {
    const JsonValue* found = v.find(v.member_names[i]);
    FUZZ_CHECK(found != nullptr);
    const std::size_t index = static_cast<std::size_t>(found - v.member_values.data());
    FUZZ_CHECK(index <= i && v.member_names[index] == v.member_names[i]);
    for (std::size_t j = 0; j < index; ++j) FUZZ_CHECK(v.member_names[j] != v.member_names[i]);
    checkFind(v.member_values[i]);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  JsonValue value;
  const bool accepted = plumb::runtime::parseJson(text, &value).ok();
  GrammarCheck grammar(text);
  const bool valid = grammar.document();
  const bool expected = valid && grammar.deepest() <= kReaderMaxDepth;
  if (accepted != expected) {
    std::fprintf(stderr, "parseJson %s a text the RFC 8259 grammar %s (deepest value %d)\n",
                 accepted ? "accepted" : "refused", valid ? "accepts" : "refuses", grammar.deepest());
    FUZZ_CHECK(accepted == expected);
  }
  if (!accepted) return 0;
  checkFind(value);
  std::string printed;
  print(value, &printed);
  JsonValue reread;
  FUZZ_CHECK(plumb::runtime::parseJson(printed, &reread).ok());
  FUZZ_CHECK(same(value, reread));
  return 0;
}
