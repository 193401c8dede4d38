#pragma once
// JsonWriter: builds one JSON text into a string (the viewer's messages, server thread only).
// Commas are placed by the writer; strings and numbers are runtime/json_text.h's (escaped; null
// for a non-finite number), numbers with 17 significant digits unless fewer are asked for.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace plumb::viewer {

class JsonWriter {
 public:
  JsonWriter& beginObject() { return open('{'); }
  JsonWriter& endObject() { return close('}'); }
  JsonWriter& beginArray() { return open('['); }
  JsonWriter& endArray() { return close(']'); }
  JsonWriter& key(std::string_view name);
  JsonWriter& string(std::string_view value);
  JsonWriter& number(double value);
  // Fewer digits where exactness does not matter and size does (drawn geometry: 7 is ~0.1 um at
  // 1 km for floats' worth of precision).
  JsonWriter& number(double value, int significant_digits);
  JsonWriter& number(uint64_t value);
  JsonWriter& number(int value) { return number(double(value)); }
  JsonWriter& boolean(bool value);
  // A JSON text inserted as one value (e.g. a nested message built elsewhere).
  JsonWriter& raw(std::string_view json);

  const std::string& text() const { return text_; }
  void clear() {
    text_.clear();
    first_.clear();
    after_key_ = false;
  }

 private:
  void separate();
  JsonWriter& open(char c);
  JsonWriter& close(char c);

  std::string text_;
  std::vector<bool> first_;  // per open container: nothing written in it yet
  bool after_key_ = false;
};

}  // namespace plumb::viewer
