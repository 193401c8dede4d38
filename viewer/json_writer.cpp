#include "viewer/json_writer.h"

#include <cstdio>

#include "runtime/json_text.h"

namespace plumb::viewer {

void JsonWriter::separate() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (!first_.empty()) {
    if (!first_.back()) text_ += ',';
    first_.back() = false;
  }
}

JsonWriter& JsonWriter::open(char c) {
  separate();
  text_ += c;
  first_.push_back(true);
  return *this;
}

JsonWriter& JsonWriter::close(char c) {
  text_ += c;
  if (!first_.empty()) first_.pop_back();
  return *this;
}

JsonWriter& JsonWriter::key(std::string_view name) {
  string(name);
  text_ += ':';
  after_key_ = true;
  return *this;
}

JsonWriter& JsonWriter::string(std::string_view value) {
  separate();
  text_ += runtime::jsonString(std::string(value));
  return *this;
}

JsonWriter& JsonWriter::number(double value) { return number(value, 17); }

JsonWriter& JsonWriter::number(double value, int significant_digits) {
  separate();
  char format[8];
  std::snprintf(format, sizeof(format), "%%.%dg", significant_digits);
  text_ += runtime::jsonNumber(value, format);
  return *this;
}

JsonWriter& JsonWriter::number(uint64_t value) {
  separate();
  text_ += std::to_string(value);
  return *this;
}

JsonWriter& JsonWriter::boolean(bool value) {
  separate();
  text_ += value ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::raw(std::string_view json) {
  separate();
  text_ += json;
  return *this;
}

}  // namespace plumb::viewer
