#pragma once
// A minimal streaming JSON writer for reports and CLI output: objects, arrays, strings (escaped),
// integers, doubles (round-trip precision, null when not finite) and booleans.
//   JsonWriter json;
//   json.BeginObject().Key("images").Int(11).Key("name").String("a.jpg").EndObject();
//   json.str()  ->  {"images":11,"name":"a.jpg"}
#include <string>
#include <vector>

namespace reconar {

class JsonWriter {
 public:
  // indent > 0 pretty-prints with that many spaces per level.
  explicit JsonWriter(int indent = 0) : indent_(indent) {}

  JsonWriter& BeginObject();
  JsonWriter& EndObject();
  JsonWriter& BeginArray();
  JsonWriter& EndArray();
  JsonWriter& Key(const std::string& key);
  JsonWriter& String(const std::string& value);
  JsonWriter& Int(long long value);
  JsonWriter& Double(double value);
  JsonWriter& Bool(bool value);
  JsonWriter& Null();
  // A value that is already JSON (e.g. a stage's own report file), inserted as it is; trailing
  // white space is dropped.
  JsonWriter& Raw(const std::string& json_value);

  const std::string& str() const { return out_; }

 private:
  void BeforeValue();
  void NewLine();

  int indent_;
  std::string out_;
  std::vector<bool> first_in_scope_;  // per open scope: no element written yet
  bool after_key_ = false;
};

// `text` as a quoted JSON string with the required escapes.
std::string JsonQuote(const std::string& text);

}  // namespace reconar
