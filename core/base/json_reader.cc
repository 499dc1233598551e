#include "core/base/json_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "core/base/atomic_file.h"

namespace reconar {

JsonValue JsonValue::Bool(bool value) {
  JsonValue json;
  json.type_ = Type::kBool;
  json.bool_ = value;
  return json;
}

JsonValue JsonValue::Number(double value) {
  JsonValue json;
  json.type_ = Type::kNumber;
  json.number_ = value;
  return json;
}

JsonValue JsonValue::String(std::string value) {
  JsonValue json;
  json.type_ = Type::kString;
  json.string_ = std::move(value);
  return json;
}

JsonValue JsonValue::Array() {
  JsonValue json;
  json.type_ = Type::kArray;
  return json;
}

JsonValue JsonValue::Object() {
  JsonValue json;
  json.type_ = Type::kObject;
  return json;
}

bool JsonValue::bool_value() const {
  RECONAR_CHECK(is_bool()) << "JSON value is not a boolean";
  return bool_;
}

double JsonValue::number() const {
  RECONAR_CHECK(is_number()) << "JSON value is not a number";
  return number_;
}

const std::string& JsonValue::string() const {
  RECONAR_CHECK(is_string()) << "JSON value is not a string";
  return string_;
}

std::optional<int64_t> JsonValue::AsInteger() const {
  constexpr double kMaxExact = 9007199254740992.0;  // 2^53
  if (!is_number() || std::trunc(number_) != number_ || std::fabs(number_) > kMaxExact) return std::nullopt;
  return static_cast<int64_t>(number_);
}

const JsonValue& JsonValue::operator[](size_t index) const {
  RECONAR_CHECK(index < items_.size()) << "JSON index " << index << " out of range " << items_.size();
  return items_[index];
}

const std::string& JsonValue::key(size_t index) const {
  RECONAR_CHECK(is_object() && index < keys_.size()) << "JSON member " << index << " out of range";
  return keys_[index];
}

const JsonValue* JsonValue::Find(std::string_view key) const {
  for (size_t i = 0; i < keys_.size(); ++i) {
    if (keys_[i] == key) return &items_[i];
  }
  return nullptr;
}

void JsonValue::Append(JsonValue value) {
  RECONAR_CHECK(is_array()) << "Append on a JSON value that is not an array";
  items_.push_back(std::move(value));
}

void JsonValue::Add(std::string key, JsonValue value) {
  RECONAR_CHECK(is_object()) << "Add on a JSON value that is not an object";
  keys_.push_back(std::move(key));
  items_.push_back(std::move(value));
}

namespace {

// Recursive descent over RFC 8259's grammar. Each Parse* returns false after recording the first
// error (with its byte offset) in error_.
class JsonParser {
 public:
  JsonParser(std::string_view text, const std::string& name, const JsonParseOptions& options)
      : text_(text), name_(name), options_(options) {}

  Result<JsonValue> Parse() {
    if (text_.size() >= 3 && text_.substr(0, 3) == "\xEF\xBB\xBF") {
      Fail(0, "byte-order mark before the JSON text");
      return error_;
    }
    JsonValue value;
    SkipWhiteSpace();
    if (!ParseValue(0, &value)) return error_;
    SkipWhiteSpace();
    if (position_ != text_.size()) {
      Fail(position_, "unexpected " + Describe(position_) + " after the JSON value");
      return error_;
    }
    return value;
  }

 private:
  bool Fail(size_t offset, const std::string& reason) {
    error_ = CorruptData(name_ + ": byte " + std::to_string(offset) + ": " + reason);
    return false;
  }

  std::string Describe(size_t offset) const {
    if (offset >= text_.size()) return "end of input";
    const unsigned char c = static_cast<unsigned char>(text_[offset]);
    if (c >= 0x20 && c < 0x7f) return std::string("'") + static_cast<char>(c) + "'";
    char buffer[8];
    std::snprintf(buffer, sizeof(buffer), "0x%02x", c);
    return std::string("byte ") + buffer;
  }

  void SkipWhiteSpace() {
    while (position_ < text_.size()) {
      const char c = text_[position_];
      if (c != ' ' && c != '\t' && c != '\n' && c != '\r') break;
      ++position_;
    }
  }

  bool Consume(std::string_view literal) {
    if (text_.substr(position_, literal.size()) != literal) return false;
    position_ += literal.size();
    return true;
  }

  bool ParseValue(int depth, JsonValue* out) {
    if (position_ >= text_.size()) return Fail(position_, "unexpected end of input, expected a value");
    const char c = text_[position_];
    switch (c) {
      case '{': return ParseObject(depth + 1, out);
      case '[': return ParseArray(depth + 1, out);
      case '"': {
        std::string value;
        if (!ParseString(&value)) return false;
        *out = JsonValue::String(std::move(value));
        return true;
      }
      case 't':
        if (!Consume("true")) return Fail(position_, "invalid literal (expected true)");
        *out = JsonValue::Bool(true);
        return true;
      case 'f':
        if (!Consume("false")) return Fail(position_, "invalid literal (expected false)");
        *out = JsonValue::Bool(false);
        return true;
      case 'n':
        if (!Consume("null")) return Fail(position_, "invalid literal (expected null)");
        *out = JsonValue();
        return true;
      default:
        if (c == '-' || (c >= '0' && c <= '9')) return ParseNumber(out);
        return Fail(position_, "unexpected " + Describe(position_) + ", expected a value");
    }
  }

  bool CheckDepth(int depth) {
    if (depth > options_.max_depth) {
      return Fail(position_, "nesting deeper than " + std::to_string(options_.max_depth) + " levels");
    }
    return true;
  }

  bool ParseArray(int depth, JsonValue* out) {
    if (!CheckDepth(depth)) return false;
    ++position_;  // '['
    *out = JsonValue::Array();
    SkipWhiteSpace();
    if (position_ < text_.size() && text_[position_] == ']') {
      ++position_;
      return true;
    }
    while (true) {
      SkipWhiteSpace();
      JsonValue element;
      if (!ParseValue(depth, &element)) return false;
      out->Append(std::move(element));
      SkipWhiteSpace();
      if (position_ < text_.size() && text_[position_] == ',') {
        ++position_;
        continue;
      }
      if (position_ < text_.size() && text_[position_] == ']') {
        ++position_;
        return true;
      }
      return Fail(position_, "unexpected " + Describe(position_) + " in array, expected ',' or ']'");
    }
  }

  bool ParseObject(int depth, JsonValue* out) {
    if (!CheckDepth(depth)) return false;
    const size_t start = position_;
    ++position_;  // '{'
    *out = JsonValue::Object();
    SkipWhiteSpace();
    if (position_ < text_.size() && text_[position_] == '}') {
      ++position_;
      return true;
    }
    while (true) {
      SkipWhiteSpace();
      if (position_ >= text_.size() || text_[position_] != '"') {
        return Fail(position_, "unexpected " + Describe(position_) + ", expected a member name string");
      }
      std::string key;
      if (!ParseString(&key)) return false;
      SkipWhiteSpace();
      if (position_ >= text_.size() || text_[position_] != ':') {
        return Fail(position_, "unexpected " + Describe(position_) + " after member name, expected ':'");
      }
      ++position_;
      SkipWhiteSpace();
      JsonValue value;
      if (!ParseValue(depth, &value)) return false;
      out->Add(std::move(key), std::move(value));
      SkipWhiteSpace();
      if (position_ < text_.size() && text_[position_] == ',') {
        ++position_;
        continue;
      }
      if (position_ < text_.size() && text_[position_] == '}') {
        ++position_;
        return CheckUniqueKeys(*out, start);
      }
      return Fail(position_, "unexpected " + Describe(position_) + " in object, expected ',' or '}'");
    }
  }

  bool CheckUniqueKeys(const JsonValue& object, size_t start) {
    if (object.size() < 2) return true;
    std::vector<std::string_view> keys;
    keys.reserve(object.size());
    for (size_t i = 0; i < object.size(); ++i) keys.push_back(object.key(i));
    std::sort(keys.begin(), keys.end());
    const auto duplicate = std::adjacent_find(keys.begin(), keys.end());
    if (duplicate == keys.end()) return true;
    return Fail(start, "duplicate member name \"" + std::string(*duplicate) + "\" in object");
  }

  bool ParseNumber(JsonValue* out) {
    const size_t start = position_;
    const auto digits = [&] {
      const size_t first = position_;
      while (position_ < text_.size() && text_[position_] >= '0' && text_[position_] <= '9') ++position_;
      return position_ - first;
    };
    if (text_[position_] == '-') ++position_;
    if (position_ < text_.size() && text_[position_] == '0') {
      ++position_;
      if (position_ < text_.size() && text_[position_] >= '0' && text_[position_] <= '9') {
        return Fail(start, "number with a leading zero");
      }
    } else if (digits() == 0) {
      return Fail(position_, "expected a digit in number");
    }
    if (position_ < text_.size() && text_[position_] == '.') {
      ++position_;
      if (digits() == 0) return Fail(position_, "expected a digit after the decimal point");
    }
    if (position_ < text_.size() && (text_[position_] == 'e' || text_[position_] == 'E')) {
      ++position_;
      if (position_ < text_.size() && (text_[position_] == '+' || text_[position_] == '-')) ++position_;
      if (digits() == 0) return Fail(position_, "expected a digit in the exponent");
    }
    double value = 0.0;
    const char* first = text_.data() + start;
    const char* last = text_.data() + position_;
    const auto result = std::from_chars(first, last, value);
    if (result.ec == std::errc::result_out_of_range) {
      // Underflow becomes the nearest double (0 or subnormal); overflow is an error.
      value = std::strtod(std::string(first, last).c_str(), nullptr);
      if (std::isinf(value)) return Fail(start, "number out of the range of a double");
    } else if (result.ec != std::errc() || result.ptr != last) {
      return Fail(start, "malformed number");
    }
    *out = JsonValue::Number(value);
    return true;
  }

  bool ParseHex4(uint32_t* value) {
    if (text_.size() - position_ < 4) return Fail(position_, "truncated \\u escape");
    *value = 0;
    for (int i = 0; i < 4; ++i) {
      const char c = text_[position_ + i];
      uint32_t digit;
      if (c >= '0' && c <= '9') {
        digit = static_cast<uint32_t>(c - '0');
      } else if (c >= 'a' && c <= 'f') {
        digit = static_cast<uint32_t>(c - 'a' + 10);
      } else if (c >= 'A' && c <= 'F') {
        digit = static_cast<uint32_t>(c - 'A' + 10);
      } else {
        return Fail(position_ + i, "invalid hex digit in \\u escape");
      }
      *value = *value * 16 + digit;
    }
    position_ += 4;
    return true;
  }

  static void AppendUtf8(uint32_t code_point, std::string* out) {
    if (code_point < 0x80) {
      out->push_back(static_cast<char>(code_point));
    } else if (code_point < 0x800) {
      out->push_back(static_cast<char>(0xC0 | (code_point >> 6)));
      out->push_back(static_cast<char>(0x80 | (code_point & 0x3F)));
    } else if (code_point < 0x10000) {
      out->push_back(static_cast<char>(0xE0 | (code_point >> 12)));
      out->push_back(static_cast<char>(0x80 | ((code_point >> 6) & 0x3F)));
      out->push_back(static_cast<char>(0x80 | (code_point & 0x3F)));
    } else {
      out->push_back(static_cast<char>(0xF0 | (code_point >> 18)));
      out->push_back(static_cast<char>(0x80 | ((code_point >> 12) & 0x3F)));
      out->push_back(static_cast<char>(0x80 | ((code_point >> 6) & 0x3F)));
      out->push_back(static_cast<char>(0x80 | (code_point & 0x3F)));
    }
  }

  // After a backslash-u: one code point, or a surrogate pair written as two escapes.
  bool ParseUnicodeEscape(std::string* out) {
    const size_t start = position_ - 2;
    uint32_t code_point = 0;
    if (!ParseHex4(&code_point)) return false;
    if (code_point >= 0xDC00 && code_point <= 0xDFFF) return Fail(start, "unpaired low surrogate in \\u escape");
    if (code_point >= 0xD800 && code_point <= 0xDBFF) {
      if (!Consume("\\u")) return Fail(position_, "high surrogate not followed by a \\u low surrogate");
      uint32_t low = 0;
      if (!ParseHex4(&low)) return false;
      if (low < 0xDC00 || low > 0xDFFF) return Fail(position_ - 6, "high surrogate not followed by a low surrogate");
      code_point = 0x10000 + ((code_point - 0xD800) << 10) + (low - 0xDC00);
    }
    AppendUtf8(code_point, out);
    return true;
  }

  // Length of the valid UTF-8 sequence at position_ (lead byte >= 0x80), or 0 (RFC 3629).
  size_t Utf8SequenceLength() const {
    const auto byte = [&](size_t i) {
      return position_ + i < text_.size() ? static_cast<unsigned char>(text_[position_ + i]) : 0u;
    };
    const unsigned lead = byte(0);
    size_t length;
    unsigned low = 0x80, high = 0xBF;  // allowed range of the second byte
    if (lead >= 0xC2 && lead <= 0xDF) {
      length = 2;
    } else if (lead >= 0xE0 && lead <= 0xEF) {
      length = 3;
      if (lead == 0xE0) low = 0xA0;   // no overlong forms
      if (lead == 0xED) high = 0x9F;  // no UTF-16 surrogates
    } else if (lead >= 0xF0 && lead <= 0xF4) {
      length = 4;
      if (lead == 0xF0) low = 0x90;
      if (lead == 0xF4) high = 0x8F;  // nothing above U+10FFFF
    } else {
      return 0;
    }
    if (byte(1) < low || byte(1) > high) return 0;
    for (size_t i = 2; i < length; ++i) {
      if (byte(i) < 0x80 || byte(i) > 0xBF) return 0;
    }
    return length;
  }

  bool ParseString(std::string* out) {
    const size_t start = position_;
    ++position_;  // opening quote
    while (true) {
      if (position_ >= text_.size()) return Fail(start, "unterminated string");
      const unsigned char c = static_cast<unsigned char>(text_[position_]);
      if (c == '"') {
        ++position_;
        return true;
      }
      if (c < 0x20) return Fail(position_, "raw control character in string (must be escaped)");
      if (c >= 0x80) {
        const size_t length = Utf8SequenceLength();
        if (length == 0) return Fail(position_, "invalid UTF-8 in string");
        out->append(text_.data() + position_, length);
        position_ += length;
        continue;
      }
      if (c != '\\') {
        out->push_back(static_cast<char>(c));
        ++position_;
        continue;
      }
      if (position_ + 1 >= text_.size()) return Fail(start, "unterminated string");
      const char escape = text_[position_ + 1];
      position_ += 2;
      switch (escape) {
        case '"': out->push_back('"'); break;
        case '\\': out->push_back('\\'); break;
        case '/': out->push_back('/'); break;
        case 'b': out->push_back('\b'); break;
        case 'f': out->push_back('\f'); break;
        case 'n': out->push_back('\n'); break;
        case 'r': out->push_back('\r'); break;
        case 't': out->push_back('\t'); break;
        case 'u':
          if (!ParseUnicodeEscape(out)) return false;
          break;
        default: return Fail(position_ - 2, "invalid escape sequence in string");
      }
    }
  }

  std::string_view text_;
  const std::string& name_;
  const JsonParseOptions& options_;
  size_t position_ = 0;
  Status error_;
};

}  // namespace

Result<JsonValue> ParseJson(std::string_view text, const std::string& name_for_errors,
                            const JsonParseOptions& options) {
  return JsonParser(text, name_for_errors, options).Parse();
}

Result<JsonValue> ReadJsonFile(const std::string& path, const JsonParseOptions& options) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  return ParseJson(text, path, options);
}

}  // namespace reconar
