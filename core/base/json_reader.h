#pragma once
// A small, strict JSON reader (RFC 8259) building a DOM: glTF JSON chunks, our report.json and
// tags.json. The counterpart of json_writer.h.
//   Result<JsonValue> json = ParseJson(text, "tags.json");
//   const JsonValue* size = json->Find("tag_size_m");   // null when absent
//   if (size != nullptr && size->is_number()) ... size->number() ...
// Strict: one value surrounded by optional white space; no comments, trailing commas, NaN,
// leading zeros, single quotes, byte-order mark or duplicate object keys; strings must be valid
// UTF-8 without raw control characters; \uXXXX escapes (surrogate pairs included) become UTF-8.
// Numbers are doubles (std::from_chars); one that overflows a double is an error.
// Errors are kCorruptData "<name>: byte <offset>: <reason>", offset counted from 0.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"

namespace reconar {

class JsonValue {
 public:
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject };

  JsonValue() = default;  // null
  static JsonValue Bool(bool value);
  static JsonValue Number(double value);
  static JsonValue String(std::string value);
  static JsonValue Array();
  static JsonValue Object();

  Type type() const { return type_; }
  bool is_null() const { return type_ == Type::kNull; }
  bool is_bool() const { return type_ == Type::kBool; }
  bool is_number() const { return type_ == Type::kNumber; }
  bool is_string() const { return type_ == Type::kString; }
  bool is_array() const { return type_ == Type::kArray; }
  bool is_object() const { return type_ == Type::kObject; }

  // Typed access; calling one on a value of another type is a programmer error (CHECK).
  bool bool_value() const;
  double number() const;
  const std::string& string() const;

  // The number when it is an integer in [-2^53, 2^53]; nullopt for another type or value.
  std::optional<int64_t> AsInteger() const;

  // Arrays: elements; objects: members in file order. size() is 0 for other types.
  size_t size() const { return items_.size(); }
  const JsonValue& operator[](size_t index) const;  // array element or object member value (CHECK)
  const std::string& key(size_t index) const;       // object member key (CHECK)

  // The member named `key` of an object; null when absent or when this is not an object.
  const JsonValue* Find(std::string_view key) const;

  // Building (used by the parser; CHECKs the type).
  void Append(JsonValue value);                  // to an array
  void Add(std::string key, JsonValue value);    // to an object

 private:
  Type type_ = Type::kNull;
  bool bool_ = false;
  double number_ = 0.0;
  std::string string_;
  std::vector<std::string> keys_;  // object member names, parallel to items_
  std::vector<JsonValue> items_;   // array elements or object member values
};

struct JsonParseOptions {
  int max_depth = 256;  // nesting of arrays/objects beyond this is an error (bounds the recursion)
};

// Parses a complete JSON text; `name_for_errors` (a file name) prefixes every error message.
Result<JsonValue> ParseJson(std::string_view text, const std::string& name_for_errors,
                            const JsonParseOptions& options = {});

// ReadFileToString + ParseJson; errors name the file.
Result<JsonValue> ReadJsonFile(const std::string& path, const JsonParseOptions& options = {});

}  // namespace reconar
