#pragma once
// A Rigid3 in JSON: {"R": [9 numbers, row-major], "t": [3 numbers]}, the one form the commands'
// JSON (localize, track, view, tags.json) gives poses in.
#include "core/base/json_writer.h"
#include "core/math/rigid3.h"

namespace reconar {

inline JsonWriter& WriteRigid3Json(JsonWriter& json, const Rigid3& pose) {
  json.BeginObject().Key("R").BeginArray();
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) json.Double(pose.rotation(row, col));
  }
  json.EndArray().Key("t").BeginArray();
  for (int k = 0; k < 3; ++k) json.Double(pose.translation(k));
  return json.EndArray().EndObject();
}

}  // namespace reconar
