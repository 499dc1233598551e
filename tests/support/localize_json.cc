#include "tests/support/localize_json.h"

#include <sstream>

#include "core/base/json_reader.h"

namespace reconar::testing {
namespace {

// The number at `key` of `object`, or nullptr when it is missing or not a number.
const JsonValue* NumberAt(const JsonValue& object, const char* key) {
  const JsonValue* value = object.is_object() ? object.Find(key) : nullptr;
  return value != nullptr && value->is_number() ? value : nullptr;
}

// The array of `size` numbers at `key`, into out[0 .. size).
bool ReadNumbers(const JsonValue& object, const char* key, size_t size, double* out) {
  const JsonValue* array = object.is_object() ? object.Find(key) : nullptr;
  if (array == nullptr || !array->is_array() || array->size() != size) return false;
  for (size_t i = 0; i < size; ++i) {
    if (!(*array)[i].is_number()) return false;
    out[i] = (*array)[i].number();
  }
  return true;
}

Result<LocalizedPhoto> ParseLine(const JsonValue& json) {
  LocalizedPhoto photo;
  const JsonValue* registered = json.Find("registered");
  const JsonValue* reason = json.Find("reason");
  const JsonValue* inliers = NumberAt(json, "inliers");
  const JsonValue* ms = NumberAt(json, "ms");
  if (registered == nullptr || !registered->is_bool() || reason == nullptr || !reason->is_string() ||
      inliers == nullptr || ms == nullptr)
    return CorruptData("\"registered\", \"reason\", \"inliers\" or \"ms\" missing");
  photo.registered = registered->bool_value();
  photo.reason = reason->string();
  photo.inliers = static_cast<int>(inliers->number());
  photo.ms = ms->number();
  if (!photo.registered) return photo;
  const JsonValue* pose = json.Find("cam_from_world");
  const JsonValue* camera = json.Find("camera");
  double rotation[9], translation[3];
  if (pose == nullptr || camera == nullptr || !ReadNumbers(*pose, "R", 9, rotation) ||
      !ReadNumbers(*pose, "t", 3, translation))
    return CorruptData("a registered photo without \"cam_from_world\" R [9] and t [3] or \"camera\"");
  for (int i = 0; i < 9; ++i) photo.R(i / 3, i % 3) = rotation[i];
  for (int i = 0; i < 3; ++i) photo.t(i) = translation[i];
  const char* kKeys[6] = {"fx", "fy", "cx", "cy", "k1", "k2"};
  double values[6];
  for (int i = 0; i < 6; ++i) {
    const JsonValue* value = NumberAt(*camera, kKeys[i]);
    if (value == nullptr) return CorruptData(std::string("\"camera\" without \"") + kKeys[i] + "\"");
    values[i] = value->number();
  }
  if (!(values[0] > 0.0)) return CorruptData("\"camera\" with fx <= 0");
  photo.camera.focal = values[0];
  photo.camera.aspect = values[1] / values[0];
  photo.camera.cx = values[2];
  photo.camera.cy = values[3];
  photo.camera.k1 = values[4];
  photo.camera.k2 = values[5];
  return photo;
}

Result<TrackedFrame> ParseFrame(const JsonValue& json) {
  TrackedFrame frame;
  const JsonValue* name = json.Find("frame");
  const JsonValue* tags = json.Find("tags");
  const JsonValue* ms = NumberAt(json, "ms");
  if (name == nullptr || !name->is_string() || tags == nullptr || !tags->is_array() || ms == nullptr)
    return CorruptData("\"frame\", \"tags\" or \"ms\" missing");
  frame.frame = name->string();
  frame.ms = ms->number();
  for (size_t i = 0; i < tags->size(); ++i) {
    const JsonValue& tag = (*tags)[i];
    const JsonValue* id = NumberAt(tag, "id");
    const JsonValue* corners = tag.is_object() ? tag.Find("corners") : nullptr;
    if (id == nullptr || corners == nullptr || !corners->is_array() || corners->size() != 4)
      return CorruptData("a tag without \"id\" or four \"corners\"");
    TrackedFrameTag out;
    out.id = static_cast<int>(id->number());
    for (size_t k = 0; k < 4; ++k) {
      const JsonValue& corner = (*corners)[k];
      if (!corner.is_array() || corner.size() != 2 || !corner[0].is_number() || !corner[1].is_number())
        return CorruptData("a tag corner that is not [x, y]");
      out.corners[k] = Eigen::Vector2d(corner[0].number(), corner[1].number());
    }
    frame.tags.push_back(out);
  }
  const JsonValue* source = json.Find("source");
  if (source == nullptr) return frame;
  const JsonValue* state = json.Find("state");
  const JsonValue* inliers = NumberAt(json, "map_inliers");
  if (!source->is_string() || state == nullptr || !state->is_string() || inliers == nullptr)
    return CorruptData("\"source\" without \"state\" or \"map_inliers\"");
  frame.source = source->string();
  frame.state = state->string();
  frame.map_inliers = static_cast<int>(inliers->number());
  const JsonValue* units = json.Find("units");
  if (units == nullptr || !units->is_string()) return CorruptData("\"source\" without \"units\"");
  frame.units = units->string();
  if (const JsonValue* pose = json.Find("cam_from_world")) {
    double rotation[9], translation[3];
    if (!ReadNumbers(*pose, "R", 9, rotation) || !ReadNumbers(*pose, "t", 3, translation))
      return CorruptData("\"cam_from_world\" without R [9] and t [3]");
    for (int i = 0; i < 9; ++i) frame.R(i / 3, i % 3) = rotation[i];
    for (int i = 0; i < 3; ++i) frame.t(i) = translation[i];
    frame.has_pose = true;
  }
  return frame;
}

}  // namespace

Result<std::vector<TrackedFrame>> ParseTrackJson(const std::string& output) {
  std::vector<TrackedFrame> frames;
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] != '{') continue;
    RECONAR_ASSIGN_OR_RETURN(const JsonValue json, ParseJson(line, "track --json"));
    if (!json.is_object()) return CorruptData("track --json: a line that is not an object: " + line);
    auto frame = ParseFrame(json);
    if (!frame.ok()) return CorruptData("track --json: " + frame.status().message() + ": " + line);
    frames.push_back(std::move(*frame));
  }
  return frames;
}

Result<std::map<std::string, LocalizedPhoto>> ParseLocalizeJson(const std::string& output) {
  std::map<std::string, LocalizedPhoto> result;
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] != '{') continue;
    RECONAR_ASSIGN_OR_RETURN(const JsonValue json, ParseJson(line, "localize --json"));
    const JsonValue* image = json.is_object() ? json.Find("image") : nullptr;
    if (image == nullptr || !image->is_string())
      return CorruptData("localize --json: a line without \"image\": " + line);
    auto photo = ParseLine(json);
    if (!photo.ok()) return CorruptData("localize --json: " + photo.status().message() + ": " + line);
    result[image->string()] = *photo;
  }
  return result;
}

}  // namespace reconar::testing
