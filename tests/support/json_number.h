#pragma once
// A number from a report's JSON, for tests that compare it.
#include <cmath>

#include "core/base/json_reader.h"

namespace reconar::testing {

// The number `key` of a JSON object; NaN (which fails every comparison) when it is missing or not a
// number.
inline double JsonNumber(const JsonValue& object, const char* key) {
  const JsonValue* value = object.Find(key);
  return value != nullptr && value->is_number() ? value->number() : std::nan("");
}

}  // namespace reconar::testing
