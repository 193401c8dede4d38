#pragma once
// A small strict JSON reader (RFC 8259 values, UTF-8 text) for reading plumb's own files back,
// e.g. trace files in `plumb profile`. Not for hot paths: it builds a tree of heap nodes.
// Errors name the line and column.
#include <string>
#include <vector>

#include "platform/status.h"

namespace plumb::runtime {

struct JsonValue {
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject };
  Type type = Type::kNull;
  bool boolean = false;
  double number = 0.0;
  std::string string;
  std::vector<JsonValue> items;           // kArray
  std::vector<std::string> member_names;  // kObject, in file order
  std::vector<JsonValue> member_values;   // kObject, parallel to member_names

  // Member of an object by name (first match), or nullptr (also for non-objects).
  const JsonValue* find(const std::string& name) const;
  bool isNumber() const { return type == Type::kNumber; }
  bool isString() const { return type == Type::kString; }
};

// Parses a complete JSON text (one value, surrounded only by whitespace).
Status parseJson(const std::string& text, JsonValue* out);

}  // namespace plumb::runtime
