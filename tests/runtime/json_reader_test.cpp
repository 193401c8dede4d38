#include "runtime/json_reader.h"

#include <gtest/gtest.h>

namespace plumb::runtime {
namespace {

TEST(JsonReader, ParsesEveryKindOfValue) {
  JsonValue v;
  ASSERT_TRUE(parseJson(R"( {"a": [1, -2.5e3, true, false, null], "s": "x\"y\u0041\n", "o": {}} )", &v).ok());
  ASSERT_EQ(v.type, JsonValue::Type::kObject);
  const JsonValue* a = v.find("a");
  ASSERT_NE(a, nullptr);
  ASSERT_EQ(a->items.size(), 5u);
  EXPECT_EQ(a->items[0].number, 1.0);
  EXPECT_EQ(a->items[1].number, -2500.0);
  EXPECT_TRUE(a->items[2].boolean);
  EXPECT_EQ(a->items[3].type, JsonValue::Type::kBool);
  EXPECT_EQ(a->items[4].type, JsonValue::Type::kNull);
  EXPECT_EQ(v.find("s")->string, "x\"yA\n");
  EXPECT_EQ(v.find("o")->type, JsonValue::Type::kObject);
  EXPECT_EQ(v.find("missing"), nullptr);
}

TEST(JsonReader, RejectsMalformedTextWithLineAndColumn) {
  JsonValue v;
  for (const char* bad : {"", "{", "[1,]", "{\"a\" 1}", "01x", "1.", "\"abc", "[1] 2", "{'a':1}",
                          "-", "tru", "\"\\q\""}) {
    const Status status = parseJson(bad, &v);
    EXPECT_FALSE(status.ok()) << "accepted: " << bad;
    EXPECT_NE(status.message().find("line"), std::string::npos) << status.message();
  }
  const Status status = parseJson("{\n  \"a\": ]\n}", &v);
  EXPECT_NE(status.message().find("line 2 column 8"), std::string::npos) << status.message();
}

TEST(JsonReader, RefusesHostileNesting) {
  JsonValue v;
  EXPECT_FALSE(parseJson(std::string(100000, '['), &v).ok());
}

// Found by fuzz/json_reader_fuzzer.cpp (differential against the RFC 8259 grammar): a NUL byte was
// skipped as whitespace, because strchr(" \t\r\n", c) also matches the terminating NUL.
TEST(JsonReader, RefusesNulBytesOutsideStrings) {
  JsonValue v;
  for (const std::string& bad : {std::string("[1,\0 2]", 7), std::string("\0{}", 3), std::string("{}\0", 3),
                                std::string("{\"a\":\0 1}", 9)}) {
    EXPECT_FALSE(parseJson(bad, &v).ok()) << "accepted a NUL byte at offset " << bad.find('\0');
  }
  EXPECT_TRUE(parseJson(" \t\r\n[1, 2]\n", &v).ok());
}

// Found by the fuzzer: RFC 8259 numbers have no leading zeros ("01" is not JSON).
TEST(JsonReader, RefusesLeadingZeros) {
  JsonValue v;
  for (const char* bad : {"01", "-01", "[00]", "{\"a\": 007.5}", "00e1"}) {
    EXPECT_FALSE(parseJson(bad, &v).ok()) << "accepted: " << bad;
  }
  for (const char* good : {"0", "-0", "0.5", "0e3", "10", "[0, 100]"}) {
    EXPECT_TRUE(parseJson(good, &v).ok()) << "refused: " << good;
  }
  ASSERT_TRUE(parseJson("[-0.25, 0E-2, 120]", &v).ok());
  EXPECT_EQ(v.items[0].number, -0.25);
  EXPECT_EQ(v.items[1].number, 0.0);
  EXPECT_EQ(v.items[2].number, 120.0);
}

// Found by the fuzzer: \u must be followed by exactly four hex digits; strtoul also took a sign,
// spaces and a "0x" prefix ("\u-001" even produced the byte 0xFF, which is never UTF-8).
TEST(JsonReader, UnicodeEscapeNeedsFourHexDigits) {
  JsonValue v;
  for (const char* bad : {R"("\u0x12")", R"("\u+123")", R"("\u 123")", R"("\u-001")", R"("\u12g4")", R"("\u12")"}) {
    EXPECT_FALSE(parseJson(bad, &v).ok()) << "accepted: " << bad;
  }
  ASSERT_TRUE(parseJson(R"("\u0041\u00e9\u20AC")", &v).ok());
  EXPECT_EQ(v.string, "A\xc3\xa9\xe2\x82\xac");
}

}  // namespace
}  // namespace plumb::runtime
