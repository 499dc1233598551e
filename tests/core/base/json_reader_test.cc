// ParseJson: the RFC 8259 grammar, escapes to UTF-8, numbers, limits, and malformed inputs that
// must each yield CorruptData with the byte offset (never a crash); round trip with JsonWriter.
#include "core/base/json_reader.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/base/json_writer.h"

namespace reconar {
namespace {

JsonValue ParseOk(const std::string& text) {
  Result<JsonValue> json = ParseJson(text, "test.json");
  EXPECT_TRUE(json.ok()) << text << ": " << json.status().ToString();
  return json.ok() ? std::move(json).value() : JsonValue();
}

TEST(JsonReaderTest, ScalarsAndContainers) {
  EXPECT_TRUE(ParseOk("null").is_null());
  EXPECT_TRUE(ParseOk(" true ").bool_value());
  EXPECT_FALSE(ParseOk("\tfalse\r\n").bool_value());
  EXPECT_EQ(ParseOk("\"abc\"").string(), "abc");
  EXPECT_EQ(ParseOk("[]").size(), 0u);
  EXPECT_TRUE(ParseOk("[]").is_array());
  EXPECT_TRUE(ParseOk("{}").is_object());

  const JsonValue json = ParseOk(R"( {"asset": {"version": "2.0"}, "list": [1, -2.5, "x", [], {}, null],
                                     "empty": "", "flag": true} )");
  ASSERT_TRUE(json.is_object());
  ASSERT_EQ(json.size(), 4u);
  EXPECT_EQ(json.key(0), "asset");
  EXPECT_EQ(json.key(3), "flag");
  EXPECT_EQ(json.Find("asset")->Find("version")->string(), "2.0");
  EXPECT_EQ(json.Find("missing"), nullptr);
  EXPECT_EQ(json.Find("list")->Find("anything"), nullptr);  // not an object
  const JsonValue& list = *json.Find("list");
  ASSERT_EQ(list.size(), 6u);
  EXPECT_EQ(list[0].number(), 1.0);
  EXPECT_EQ(list[1].number(), -2.5);
  EXPECT_EQ(list[2].string(), "x");
  EXPECT_TRUE(list[3].is_array());
  EXPECT_TRUE(list[4].is_object());
  EXPECT_TRUE(list[5].is_null());
  EXPECT_EQ(json.Find("empty")->string(), "");
}

TEST(JsonReaderTest, Numbers) {
  EXPECT_EQ(ParseOk("0").number(), 0.0);
  EXPECT_TRUE(std::signbit(ParseOk("-0").number()));
  EXPECT_EQ(ParseOk("0.1").number(), 0.1);
  EXPECT_EQ(ParseOk("1e3").number(), 1000.0);
  EXPECT_EQ(ParseOk("1E+3").number(), 1000.0);
  EXPECT_EQ(ParseOk("-12.5e-1").number(), -1.25);
  EXPECT_EQ(ParseOk("1.7976931348623157e308").number(), 1.7976931348623157e308);
  EXPECT_EQ(ParseOk("4.9e-324").number(), 4.9e-324);
  EXPECT_EQ(ParseOk("1e-400").number(), 0.0);  // underflow rounds to zero
  EXPECT_EQ(ParseOk("123456789012345678").number(), 123456789012345678.0);
  EXPECT_EQ(ParseOk("34962").AsInteger(), 34962);
  EXPECT_EQ(ParseOk("-7").AsInteger(), -7);
  EXPECT_EQ(ParseOk("9007199254740992").AsInteger(), 9007199254740992);
  EXPECT_FALSE(ParseOk("1.5").AsInteger().has_value());
  EXPECT_FALSE(ParseOk("1e300").AsInteger().has_value());
  EXPECT_FALSE(ParseOk("\"3\"").AsInteger().has_value());
}

TEST(JsonReaderTest, StringEscapesBecomeUtf8) {
  EXPECT_EQ(ParseOk(R"("a\"b\\c\/d\b\f\n\r\t")").string(), "a\"b\\c/d\b\f\n\r\t");
  EXPECT_EQ(ParseOk(R"("\u0041\u00e9\u20AC")").string(), "A\xC3\xA9\xE2\x82\xAC");    // A é €
  EXPECT_EQ(ParseOk(R"("\ud83d\ude00")").string(), "\xF0\x9F\x98\x80");               // U+1F600
  EXPECT_EQ(ParseOk(R"("\uDBFF\uDFFF")").string(), "\xF4\x8F\xBF\xBF");               // U+10FFFF
  EXPECT_EQ(ParseOk(R"("\u0000")").string(), std::string(1, '\0'));
  EXPECT_EQ(ParseOk("\"\xC3\xA9\xF0\x9F\x98\x80\"").string(), "\xC3\xA9\xF0\x9F\x98\x80");  // raw UTF-8 kept
}

TEST(JsonReaderTest, RoundTripWithJsonWriter) {
  JsonWriter writer(2);
  writer.BeginObject()
      .Key("name").String("tag \"A\"\n\x01 é")
      .Key("values").BeginArray().Double(0.1).Double(-1e-300).Double(1.0 / 3.0).Int(-42).EndArray()
      .Key("ok").Bool(true)
      .Key("none").Null()
      .Key("nested").BeginObject().Key("deep").BeginArray().BeginArray().EndArray().EndArray().EndObject()
      .EndObject();
  const JsonValue json = ParseOk(writer.str());
  EXPECT_EQ(json.Find("name")->string(), "tag \"A\"\n\x01 é");
  const JsonValue& values = *json.Find("values");
  ASSERT_EQ(values.size(), 4u);
  EXPECT_EQ(values[0].number(), 0.1);
  EXPECT_EQ(values[1].number(), -1e-300);
  EXPECT_EQ(values[2].number(), 1.0 / 3.0);
  EXPECT_EQ(values[3].AsInteger(), -42);
  EXPECT_TRUE(json.Find("ok")->bool_value());
  EXPECT_TRUE(json.Find("none")->is_null());
  EXPECT_EQ((*json.Find("nested")->Find("deep"))[0].size(), 0u);
}

TEST(JsonReaderTest, DepthLimit) {
  const std::string deep_ok = std::string(256, '[') + std::string(256, ']');
  EXPECT_TRUE(ParseJson(deep_ok, "deep").ok());
  const std::string too_deep = std::string(257, '[') + std::string(257, ']');
  const Result<JsonValue> json = ParseJson(too_deep, "deep");
  ASSERT_FALSE(json.ok());
  EXPECT_EQ(json.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(json.status().message().find("byte 256"), std::string::npos) << json.status().message();
  // A hostile depth far beyond the limit fails cleanly, without exhausting the stack.
  EXPECT_FALSE(ParseJson(std::string(1000000, '['), "hostile").ok());
  JsonParseOptions shallow;
  shallow.max_depth = 2;
  EXPECT_TRUE(ParseJson("{\"a\": [1]}", "x", shallow).ok());
  EXPECT_FALSE(ParseJson("{\"a\": [[1]]}", "x", shallow).ok());
}

TEST(JsonReaderTest, MalformedInputsReportTheByteOffset) {
  const struct {
    std::string text;
    size_t offset;
  } cases[] = {
      {"", 0},                         // no value
      {"   ", 3},                      // only white space
      {"nul", 0},                      // truncated literal
      {"True", 0},                     // case matters
      {"[1,]", 3},                     // trailing comma
      {"[1 2]", 3},                    // missing comma
      {"{\"a\" 1}", 5},                // missing colon
      {"{\"a\":1,}", 7},               // trailing comma in object
      {"{a:1}", 1},                    // unquoted key
      {"{'a':1}", 1},                  // single quotes
      {"{\"a\":1}x", 7},               // trailing garbage
      {"[1] [2]", 4},                  // two values
      {"01", 0},                       // leading zero
      {"-", 1},                        // sign alone
      {"1.", 2},                       // no fraction digits
      {".5", 0},                       // no integer part
      {"1e", 2},                       // no exponent digits
      {"+1", 0},                       // plus sign
      {"NaN", 0},                      // not JSON
      {"Infinity", 0},                 // not JSON
      {"1e400", 0},                    // overflow
      {"\"abc", 0},                    // unterminated string
      {"\"a\nb\"", 2},                 // raw control character
      {"\"\\x\"", 1},                  // bad escape
      {"\"\\u12g4\"", 5},              // bad hex digit
      {"\"\\u12\"", 3},                // short \u escape  (the closing quote is not a hex digit)
      {"\"\\ud800\"", 7},              // high surrogate alone
      {"\"\\ud800\\u0041\"", 7},       // high surrogate + non-surrogate
      {"\"\\udc00\"", 1},              // low surrogate alone
      {"\"\xC3\"", 1},                 // truncated UTF-8
      {"\"\xC0\x80\"", 1},             // overlong NUL
      {"\"\xED\xA0\x80\"", 1},         // encoded surrogate
      {"\"\xF4\x90\x80\x80\"", 1},     // above U+10FFFF
      {"\"\xFF\"", 1},                 // never valid
      {"\xEF\xBB\xBF{}", 0},           // byte-order mark
      {"{\"a\":1,\"b\":2,\"a\":3}", 0},  // duplicate key
      {"[1,/*c*/2]", 3},               // comment
  };
  for (const auto& c : cases) {
    const Result<JsonValue> json = ParseJson(c.text, "bad.json");
    ASSERT_FALSE(json.ok()) << "accepted: " << c.text;
    EXPECT_EQ(json.status().code(), StatusCode::kCorruptData);
    const std::string expected = "bad.json: byte " + std::to_string(c.offset) + ":";
    EXPECT_EQ(json.status().message().rfind(expected, 0), 0u)
        << c.text << " -> " << json.status().message() << " (expected " << expected << ")";
  }
}

TEST(JsonReaderTest, ReadJsonFileNamesTheFile) {
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/reconar_json_reader_" + std::to_string(::getpid()) + ".json";
  std::ofstream(path) << "{\"tags\": [1, 2, 3]}";
  const Result<JsonValue> json = ReadJsonFile(path);
  ASSERT_TRUE(json.ok()) << json.status().ToString();
  EXPECT_EQ(json->Find("tags")->size(), 3u);
  std::ofstream(path) << "{\"tags\": [1, 2, 3}";
  const Result<JsonValue> bad = ReadJsonFile(path);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message().rfind(path + ": byte 17:", 0), 0u) << bad.status().message();
  std::filesystem::remove(path);
  EXPECT_EQ(ReadJsonFile(path).status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace reconar
