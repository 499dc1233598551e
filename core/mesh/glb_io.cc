#include "core/mesh/glb_io.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "core/base/json_writer.h"
#include "core/mesh/byte_order.h"

namespace reconar {

using mesh_internal::AppendLittleEndian;
using mesh_internal::LoadLittleEndian;

namespace {

// GLB container (glTF 2.0 specification, section 4.4 "Binary glTF Layout").
constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kGlbVersion = 2;
constexpr uint32_t kChunkJson = 0x4E4F534A;     // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;      // "BIN\0"
constexpr size_t kGlbHeaderBytes = 12;
constexpr size_t kChunkHeaderBytes = 8;

// Enumerations of the glTF schema.
constexpr int kComponentByte = 5120;
constexpr int kComponentUnsignedByte = 5121;
constexpr int kComponentShort = 5122;
constexpr int kComponentUnsignedShort = 5123;
constexpr int kComponentUnsignedInt = 5125;
constexpr int kComponentFloat = 5126;
constexpr int kTargetArrayBuffer = 34962;
constexpr int kTargetElementArrayBuffer = 34963;
constexpr int kModePoints = 0;
constexpr int kModeTriangles = 4;
constexpr int64_t kMaxByteStride = 252;

size_t Align4(size_t size) { return (size + 3) & ~size_t{3}; }

// ---------------------------------------------------------------------------------------------
// Writing.

struct BufferViewSpec {
  size_t offset;
  size_t length;
  int target;
};

Status CheckFinite(const std::vector<Eigen::Vector3f>& vectors, const char* what) {
  for (size_t i = 0; i < vectors.size(); ++i) {
    if (!vectors[i].allFinite()) {
      return InvalidArgument(std::string("mesh: ") + what + " " + std::to_string(i) + " is not finite");
    }
  }
  return Status::Ok();
}

void WriteAccessor(JsonWriter* json, int buffer_view, int component_type, size_t count, const char* type) {
  json->BeginObject()
      .Key("bufferView").Int(buffer_view)
      .Key("componentType").Int(component_type)
      .Key("count").Int(static_cast<long long>(count))
      .Key("type").String(type);
}

}  // namespace

Result<std::string> EncodeGlb(const Mesh& mesh) {
  RECONAR_RETURN_IF_ERROR(ValidateMesh(mesh));
  if (mesh.positions.empty()) return InvalidArgument("mesh: no vertices (glTF accessors need at least one)");
  RECONAR_RETURN_IF_ERROR(CheckFinite(mesh.positions, "position"));
  RECONAR_RETURN_IF_ERROR(CheckFinite(mesh.normals, "normal"));
  const size_t num_vertices = mesh.positions.size();
  // The largest value of the index type is reserved (primitive restart), so uint32 indices reach
  // 2^32 - 2 and uint16 indices 65534.
  if (num_vertices > std::numeric_limits<uint32_t>::max()) {
    return InvalidArgument("mesh: " + std::to_string(num_vertices) + " vertices exceed glTF's uint32 indices");
  }
  const bool short_indices = num_vertices <= std::numeric_limits<uint16_t>::max();

  // BIN chunk: positions, normals, colours, indices; each view 4-byte aligned.
  std::string bin;
  std::vector<BufferViewSpec> views;
  const auto begin_view = [&] { return bin.size(); };
  const auto end_view = [&](size_t offset, int target) {
    views.push_back({offset, bin.size() - offset, target});
    bin.resize(Align4(bin.size()), '\0');
  };
  Eigen::Vector3f min = mesh.positions[0], max = mesh.positions[0];
  size_t offset = begin_view();
  for (const Eigen::Vector3f& p : mesh.positions) {
    for (int axis = 0; axis < 3; ++axis) AppendLittleEndian(&bin, p[axis]);
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  end_view(offset, kTargetArrayBuffer);
  if (!mesh.normals.empty()) {
    offset = begin_view();
    for (const Eigen::Vector3f& n : mesh.normals) {
      for (int axis = 0; axis < 3; ++axis) AppendLittleEndian(&bin, n[axis]);
    }
    end_view(offset, kTargetArrayBuffer);
  }
  if (!mesh.colors.empty()) {
    offset = begin_view();
    for (const std::array<uint8_t, 4>& c : mesh.colors) bin.append(reinterpret_cast<const char*>(c.data()), 4);
    end_view(offset, kTargetArrayBuffer);
  }
  if (!mesh.triangles.empty()) {
    offset = begin_view();
    for (const std::array<uint32_t, 3>& triangle : mesh.triangles) {
      for (const uint32_t index : triangle) {
        if (short_indices) {
          AppendLittleEndian(&bin, static_cast<uint16_t>(index));
        } else {
          AppendLittleEndian(&bin, index);
        }
      }
    }
    end_view(offset, kTargetElementArrayBuffer);
  }

  JsonWriter json;
  json.BeginObject();
  json.Key("asset").BeginObject().Key("version").String("2.0").Key("generator").String("reconar").EndObject();
  json.Key("scene").Int(0);
  json.Key("scenes").BeginArray().BeginObject().Key("nodes").BeginArray().Int(0).EndArray().EndObject().EndArray();
  json.Key("nodes").BeginArray().BeginObject().Key("mesh").Int(0).EndObject().EndArray();

  int accessor = 0;
  json.Key("meshes").BeginArray().BeginObject().Key("primitives").BeginArray().BeginObject();
  json.Key("attributes").BeginObject().Key("POSITION").Int(accessor++);
  if (!mesh.normals.empty()) json.Key("NORMAL").Int(accessor++);
  if (!mesh.colors.empty()) json.Key("COLOR_0").Int(accessor++);
  json.EndObject();
  if (!mesh.triangles.empty()) json.Key("indices").Int(accessor++);
  json.Key("mode").Int(mesh.triangles.empty() ? kModePoints : kModeTriangles);
  json.EndObject().EndArray().EndObject().EndArray();

  int view = 0;
  json.Key("accessors").BeginArray();
  WriteAccessor(&json, view++, kComponentFloat, num_vertices, "VEC3");
  json.Key("min").BeginArray().Double(min.x()).Double(min.y()).Double(min.z()).EndArray();
  json.Key("max").BeginArray().Double(max.x()).Double(max.y()).Double(max.z()).EndArray();
  json.EndObject();
  if (!mesh.normals.empty()) {
    WriteAccessor(&json, view++, kComponentFloat, num_vertices, "VEC3");
    json.EndObject();
  }
  if (!mesh.colors.empty()) {
    WriteAccessor(&json, view++, kComponentUnsignedByte, num_vertices, "VEC4");
    json.Key("normalized").Bool(true).EndObject();
  }
  if (!mesh.triangles.empty()) {
    WriteAccessor(&json, view++, short_indices ? kComponentUnsignedShort : kComponentUnsignedInt,
                  3 * mesh.triangles.size(), "SCALAR");
    json.EndObject();
  }
  json.EndArray();

  json.Key("bufferViews").BeginArray();
  for (const BufferViewSpec& spec : views) {
    json.BeginObject()
        .Key("buffer").Int(0)
        .Key("byteOffset").Int(static_cast<long long>(spec.offset))
        .Key("byteLength").Int(static_cast<long long>(spec.length))
        .Key("target").Int(spec.target)
        .EndObject();
  }
  json.EndArray();
  json.Key("buffers").BeginArray().BeginObject().Key("byteLength").Int(static_cast<long long>(bin.size()));
  json.EndObject().EndArray();
  json.EndObject();

  std::string json_chunk = json.str();
  json_chunk.resize(Align4(json_chunk.size()), ' ');
  const size_t total = kGlbHeaderBytes + kChunkHeaderBytes + json_chunk.size() + kChunkHeaderBytes + bin.size();
  if (total > std::numeric_limits<uint32_t>::max()) {
    return InvalidArgument("mesh: " + std::to_string(total) + " bytes exceed the 4 GiB limit of a .glb file");
  }
  std::string glb;
  glb.reserve(total);
  AppendLittleEndian(&glb, kGlbMagic);
  AppendLittleEndian(&glb, kGlbVersion);
  AppendLittleEndian(&glb, static_cast<uint32_t>(total));
  AppendLittleEndian(&glb, static_cast<uint32_t>(json_chunk.size()));
  AppendLittleEndian(&glb, kChunkJson);
  glb += json_chunk;
  AppendLittleEndian(&glb, static_cast<uint32_t>(bin.size()));
  AppendLittleEndian(&glb, kChunkBin);
  glb += bin;
  return glb;
}

Status WriteGlb(const std::string& path, const Mesh& mesh) {
  Result<std::string> glb = EncodeGlb(mesh);
  if (!glb.ok()) return glb.status().WithContext(path);
  return WriteFileAtomically(path, *glb);
}

// ---------------------------------------------------------------------------------------------
// Reading.

namespace {

class GlbDecoder {
 public:
  GlbDecoder(std::string_view bytes, const std::string& name) : bytes_(bytes), name_(name) {}

  Result<Mesh> Decode() {
    RECONAR_RETURN_IF_ERROR(ReadContainer());
    RECONAR_RETURN_IF_ERROR(CheckAssetAndExtensions());
    const JsonValue* primitive = nullptr;
    RECONAR_RETURN_IF_ERROR(FindFirstPrimitive(&primitive));
    return ReadPrimitive(*primitive);
  }

 private:
  Status Corrupt(const std::string& reason) const { return FileError(StatusCode::kCorruptData, name_, reason); }
  Status Unsupported(const std::string& reason) const {
    return FileError(StatusCode::kUnsupported, name_, reason);
  }

  Status ReadContainer() {
    if (bytes_.size() < kGlbHeaderBytes) return Corrupt("too short for a GLB header (not a .glb file)");
    if (LoadLittleEndian<uint32_t>(bytes_.data()) != kGlbMagic) return Corrupt("no 'glTF' magic (not a .glb file)");
    const uint32_t version = LoadLittleEndian<uint32_t>(bytes_.data() + 4);
    if (version != kGlbVersion) return Unsupported("GLB container version " + std::to_string(version));
    const uint32_t length = LoadLittleEndian<uint32_t>(bytes_.data() + 8);
    if (length > bytes_.size()) {
      return Corrupt("truncated: the header declares " + std::to_string(length) + " bytes, the file has " +
                     std::to_string(bytes_.size()));
    }
    size_t position = kGlbHeaderBytes;
    bool first = true;
    while (position < length) {
      if (length - position < kChunkHeaderBytes) return Corrupt("truncated chunk header at byte " + std::to_string(position));
      const uint32_t chunk_length = LoadLittleEndian<uint32_t>(bytes_.data() + position);
      const uint32_t chunk_type = LoadLittleEndian<uint32_t>(bytes_.data() + position + 4);
      position += kChunkHeaderBytes;
      if (chunk_length > length - position) {
        return Corrupt("chunk at byte " + std::to_string(position - kChunkHeaderBytes) + " runs past the end");
      }
      const std::string_view data = bytes_.substr(position, chunk_length);
      if (first && chunk_type != kChunkJson) return Corrupt("the first chunk is not JSON");
      if (first) {
        Result<JsonValue> json = ParseJson(data, name_ + " (JSON chunk)");
        if (!json.ok()) return json.status();
        json_ = std::move(json).value();
        if (!json_.is_object()) return Corrupt("the JSON chunk is not an object");
      } else if (chunk_type == kChunkBin && !has_bin_) {
        bin_ = data;
        has_bin_ = true;
      }  // other chunk types are skipped, as the specification asks
      first = false;
      position = std::min<size_t>(Align4(position + chunk_length), length);
    }
    if (first) return Corrupt("no JSON chunk");
    return Status::Ok();
  }

  Status CheckAssetAndExtensions() {
    const JsonValue* asset = json_.Find("asset");
    const JsonValue* version = asset != nullptr ? asset->Find("version") : nullptr;
    if (version == nullptr || !version->is_string()) return Corrupt("asset.version missing");
    if (version->string().rfind("2.", 0) != 0) return Unsupported("glTF version " + version->string());
    if (const JsonValue* required = json_.Find("extensionsRequired")) {
      if (required->is_array() && required->size() > 0) {
        std::string names;
        for (size_t i = 0; i < required->size(); ++i) {
          if ((*required)[i].is_string()) names += (names.empty() ? "" : ", ") + (*required)[i].string();
        }
        return Unsupported("requires glTF extensions we do not read: " + names);
      }
    }
    return Status::Ok();
  }

  // An array member of the root; null when absent.
  const JsonValue* RootArray(const char* key) const {
    const JsonValue* value = json_.Find(key);
    return value != nullptr && value->is_array() ? value : nullptr;
  }

  // A non-negative integer member; `where` names it in messages ("accessors[2].count").
  Status GetIndex(const JsonValue& object, const char* key, const std::string& where, int64_t* out,
                  std::optional<int64_t> default_value = std::nullopt) const {
    const JsonValue* value = object.Find(key);
    if (value == nullptr) {
      if (default_value.has_value()) {
        *out = *default_value;
        return Status::Ok();
      }
      return Corrupt(where + "." + key + " missing");
    }
    const std::optional<int64_t> integer = value->AsInteger();
    if (!integer.has_value() || *integer < 0) return Corrupt(where + "." + key + " is not a non-negative integer");
    *out = *integer;
    return Status::Ok();
  }

  Status FindFirstPrimitive(const JsonValue** primitive) const {
    const JsonValue* meshes = RootArray("meshes");
    if (meshes == nullptr || meshes->size() == 0) return Corrupt("no meshes");
    const JsonValue* primitives = (*meshes)[0].Find("primitives");
    if (primitives == nullptr || !primitives->is_array() || primitives->size() == 0 || !(*primitives)[0].is_object()) {
      return Corrupt("meshes[0].primitives missing or empty");
    }
    *primitive = &(*primitives)[0];
    return Status::Ok();
  }

  // One accessor's elements as bytes: `count` elements of `components` components of
  // `component_size` bytes, `stride` bytes apart; `data` null when the accessor has no buffer
  // view (all zeros, as the specification defines).
  struct AccessorView {
    const char* data = nullptr;
    size_t count = 0;
    size_t stride = 0;
    int components = 0;
    int component_type = 0;
    bool normalized = false;
    std::string where;
  };

  static int ComponentSize(int component_type) {
    switch (component_type) {
      case kComponentByte:
      case kComponentUnsignedByte: return 1;
      case kComponentShort:
      case kComponentUnsignedShort: return 2;
      case kComponentUnsignedInt:
      case kComponentFloat: return 4;
      default: return 0;
    }
  }

  Status GetAccessor(int64_t index, AccessorView* view) const {
    const JsonValue* accessors = RootArray("accessors");
    const std::string where = "accessors[" + std::to_string(index) + "]";
    if (accessors == nullptr || index >= static_cast<int64_t>(accessors->size())) return Corrupt(where + " missing");
    const JsonValue& accessor = (*accessors)[static_cast<size_t>(index)];
    if (!accessor.is_object()) return Corrupt(where + " is not an object");
    if (accessor.Find("sparse") != nullptr) return Unsupported(where + " is sparse");
    view->where = where;
    int64_t component_type = 0, count = 0, byte_offset = 0;
    RECONAR_RETURN_IF_ERROR(GetIndex(accessor, "componentType", where, &component_type));
    RECONAR_RETURN_IF_ERROR(GetIndex(accessor, "count", where, &count));
    RECONAR_RETURN_IF_ERROR(GetIndex(accessor, "byteOffset", where, &byte_offset, 0));
    const int component_size = ComponentSize(static_cast<int>(component_type));
    if (component_size == 0) return Corrupt(where + ".componentType " + std::to_string(component_type) + " invalid");
    if (count < 1) return Corrupt(where + ".count must be at least 1");
    const JsonValue* type = accessor.Find("type");
    if (type == nullptr || !type->is_string()) return Corrupt(where + ".type missing");
    const std::string& type_name = type->string();
    if (type_name == "SCALAR") {
      view->components = 1;
    } else if (type_name == "VEC2" || type_name == "VEC3" || type_name == "VEC4") {
      view->components = type_name[3] - '0';
    } else {
      return Unsupported(where + ".type " + type_name);
    }
    const JsonValue* normalized = accessor.Find("normalized");
    view->normalized = normalized != nullptr && normalized->is_bool() && normalized->bool_value();
    view->component_type = static_cast<int>(component_type);
    view->count = static_cast<size_t>(count);
    const size_t element_size = static_cast<size_t>(component_size) * static_cast<size_t>(view->components);
    view->stride = element_size;

    if (accessor.Find("bufferView") == nullptr) {
      view->data = nullptr;
      if (view->count > bytes_.size()) return Corrupt(where + ".count " + std::to_string(count) + " without data");
      return Status::Ok();
    }
    int64_t view_index = 0;
    RECONAR_RETURN_IF_ERROR(GetIndex(accessor, "bufferView", where, &view_index));
    const JsonValue* buffer_views = RootArray("bufferViews");
    const std::string view_where = "bufferViews[" + std::to_string(view_index) + "]";
    if (buffer_views == nullptr || view_index >= static_cast<int64_t>(buffer_views->size())) {
      return Corrupt(view_where + " missing");
    }
    const JsonValue& buffer_view = (*buffer_views)[static_cast<size_t>(view_index)];
    int64_t buffer_index = 0, view_offset = 0, view_length = 0, byte_stride = 0;
    RECONAR_RETURN_IF_ERROR(GetIndex(buffer_view, "buffer", view_where, &buffer_index));
    RECONAR_RETURN_IF_ERROR(GetIndex(buffer_view, "byteOffset", view_where, &view_offset, 0));
    RECONAR_RETURN_IF_ERROR(GetIndex(buffer_view, "byteLength", view_where, &view_length));
    RECONAR_RETURN_IF_ERROR(GetIndex(buffer_view, "byteStride", view_where, &byte_stride, 0));
    if (byte_stride != 0) {
      if (byte_stride > kMaxByteStride || static_cast<size_t>(byte_stride) < element_size) {
        return Corrupt(view_where + ".byteStride " + std::to_string(byte_stride) + " invalid for " + where);
      }
      view->stride = static_cast<size_t>(byte_stride);
    }
    std::string_view buffer;
    RECONAR_RETURN_IF_ERROR(GetBuffer(buffer_index, &buffer));
    if (static_cast<uint64_t>(view_offset) > buffer.size() ||
        static_cast<uint64_t>(view_length) > buffer.size() - static_cast<uint64_t>(view_offset)) {
      return Corrupt(view_where + " lies outside buffers[" + std::to_string(buffer_index) + "]");
    }
    // count <= view_length keeps the products below 2^61.
    const uint64_t needed = static_cast<uint64_t>(byte_offset) +
                            (static_cast<uint64_t>(view->count) - 1) * view->stride + element_size;
    if (static_cast<uint64_t>(count) > static_cast<uint64_t>(view_length) ||
        needed > static_cast<uint64_t>(view_length)) {
      return Corrupt(where + " (" + std::to_string(count) + " x " + type_name + ") runs past the end of " +
                     view_where);
    }
    view->data = buffer.data() + view_offset + byte_offset;
    return Status::Ok();
  }

  Status GetBuffer(int64_t index, std::string_view* buffer) const {
    const JsonValue* buffers = RootArray("buffers");
    const std::string where = "buffers[" + std::to_string(index) + "]";
    if (buffers == nullptr || index >= static_cast<int64_t>(buffers->size())) return Corrupt(where + " missing");
    const JsonValue& entry = (*buffers)[static_cast<size_t>(index)];
    if (entry.Find("uri") != nullptr) return Unsupported(where + " has a uri (external or data: URI buffers)");
    if (index != 0) return Corrupt(where + " has no uri, but only buffers[0] can be the GLB's BIN chunk");
    if (!has_bin_) return Corrupt("buffers[0] refers to the BIN chunk, but the file has none");
    int64_t length = 0;
    RECONAR_RETURN_IF_ERROR(GetIndex(entry, "byteLength", where, &length));
    if (static_cast<uint64_t>(length) > bin_.size()) {
      return Corrupt(where + ".byteLength " + std::to_string(length) + " exceeds the BIN chunk (" +
                     std::to_string(bin_.size()) + " bytes)");
    }
    *buffer = bin_.substr(0, static_cast<size_t>(length));
    return Status::Ok();
  }

  // Component `c` of element `i` as the float the specification defines (normalized integers
  // map to [0, 1] or [-1, 1]).
  static float Component(const AccessorView& view, size_t i, int c) {
    if (view.data == nullptr) return 0.0f;
    const char* p = view.data + i * view.stride + static_cast<size_t>(c) * ComponentSize(view.component_type);
    switch (view.component_type) {
      case kComponentFloat: return LoadLittleEndian<float>(p);
      case kComponentUnsignedByte: {
        const float v = static_cast<uint8_t>(*p);
        return view.normalized ? v / 255.0f : v;
      }
      case kComponentByte: {
        const float v = static_cast<int8_t>(*p);
        return view.normalized ? std::max(v / 127.0f, -1.0f) : v;
      }
      case kComponentUnsignedShort: {
        const float v = LoadLittleEndian<uint16_t>(p);
        return view.normalized ? v / 65535.0f : v;
      }
      case kComponentShort: {
        const float v = LoadLittleEndian<int16_t>(p);
        return view.normalized ? std::max(v / 32767.0f, -1.0f) : v;
      }
      default: return static_cast<float>(LoadLittleEndian<uint32_t>(p));
    }
  }

  Status ReadVectors(const AccessorView& view, std::vector<Eigen::Vector3f>* out) const {
    if (view.components != 3) return Corrupt(view.where + " must be VEC3");
    out->resize(view.count);
    for (size_t i = 0; i < view.count; ++i) {
      for (int c = 0; c < 3; ++c) (*out)[i][c] = Component(view, i, c);
    }
    return Status::Ok();
  }

  Status ReadColors(const AccessorView& view, std::vector<std::array<uint8_t, 4>>* out) const {
    if (view.components != 3 && view.components != 4) return Corrupt(view.where + " must be VEC3 or VEC4");
    const bool valid_type = view.component_type == kComponentFloat ||
                            (view.normalized && (view.component_type == kComponentUnsignedByte ||
                                                 view.component_type == kComponentUnsignedShort));
    if (!valid_type) return Corrupt(view.where + ": COLOR_0 must be float or normalized unsigned byte/short");
    out->resize(view.count);
    for (size_t i = 0; i < view.count; ++i) {
      std::array<uint8_t, 4>& color = (*out)[i];
      color[3] = 255;
      for (int c = 0; c < view.components; ++c) {
        if (view.component_type == kComponentUnsignedByte && view.data != nullptr) {
          color[c] = static_cast<uint8_t>(view.data[i * view.stride + static_cast<size_t>(c)]);  // exact
          continue;
        }
        const float v = Component(view, i, c);
        color[c] = !(v > 0.0f) ? 0 : v >= 1.0f ? 255 : static_cast<uint8_t>(std::lround(v * 255.0f));
      }
    }
    return Status::Ok();
  }

  Result<Mesh> ReadPrimitive(const JsonValue& primitive) const {
    if (const JsonValue* extensions = primitive.Find("extensions")) {
      if (extensions->Find("KHR_draco_mesh_compression") != nullptr) {
        return Unsupported("meshes[0].primitives[0] is draco-compressed (KHR_draco_mesh_compression)");
      }
    }
    int64_t mode = kModeTriangles;
    RECONAR_RETURN_IF_ERROR(GetIndex(primitive, "mode", "meshes[0].primitives[0]", &mode, kModeTriangles));
    if (mode != kModeTriangles && mode != kModePoints) {
      return Unsupported("primitive mode " + std::to_string(mode) + " (only TRIANGLES and POINTS are read)");
    }
    const JsonValue* attributes = primitive.Find("attributes");
    if (attributes == nullptr || !attributes->is_object()) return Corrupt("meshes[0].primitives[0].attributes missing");

    Mesh mesh;
    const std::string where = "meshes[0].primitives[0].attributes";
    int64_t index = 0;
    RECONAR_RETURN_IF_ERROR(GetIndex(*attributes, "POSITION", where, &index));
    AccessorView view;
    RECONAR_RETURN_IF_ERROR(GetAccessor(index, &view));
    RECONAR_RETURN_IF_ERROR(ReadVectors(view, &mesh.positions));
    const size_t num_vertices = mesh.positions.size();
    if (attributes->Find("NORMAL") != nullptr) {
      RECONAR_RETURN_IF_ERROR(GetIndex(*attributes, "NORMAL", where, &index));
      RECONAR_RETURN_IF_ERROR(GetAccessor(index, &view));
      if (view.count != num_vertices) return Corrupt(view.where + ": NORMAL count differs from POSITION count");
      RECONAR_RETURN_IF_ERROR(ReadVectors(view, &mesh.normals));
    }
    if (attributes->Find("COLOR_0") != nullptr) {
      RECONAR_RETURN_IF_ERROR(GetIndex(*attributes, "COLOR_0", where, &index));
      RECONAR_RETURN_IF_ERROR(GetAccessor(index, &view));
      if (view.count != num_vertices) return Corrupt(view.where + ": COLOR_0 count differs from POSITION count");
      RECONAR_RETURN_IF_ERROR(ReadColors(view, &mesh.colors));
    }

    const bool indexed = primitive.Find("indices") != nullptr;
    if (mode == kModePoints) {
      if (indexed) return Unsupported("indexed POINTS primitive");
      return mesh;
    }
    if (!indexed) {
      if (num_vertices % 3 != 0) return Corrupt("non-indexed TRIANGLES with a vertex count not divisible by 3");
      for (uint32_t i = 0; i < num_vertices; i += 3) mesh.triangles.push_back({i, i + 1, i + 2});
      return mesh;
    }
    RECONAR_RETURN_IF_ERROR(GetIndex(primitive, "indices", "meshes[0].primitives[0]", &index));
    RECONAR_RETURN_IF_ERROR(GetAccessor(index, &view));
    if (view.components != 1 || view.normalized ||
        (view.component_type != kComponentUnsignedByte && view.component_type != kComponentUnsignedShort &&
         view.component_type != kComponentUnsignedInt)) {
      return Corrupt(view.where + ": indices must be unsigned byte/short/int SCALAR");
    }
    if (view.count % 3 != 0) return Corrupt(view.where + ".count " + std::to_string(view.count) + " is not a multiple of 3");
    mesh.triangles.resize(view.count / 3);
    for (size_t i = 0; i < view.count; ++i) {
      const uint32_t vertex = ReadIndex(view, i);
      if (vertex >= num_vertices) {
        return Corrupt(view.where + ": index " + std::to_string(i) + " is vertex " + std::to_string(vertex) +
                       ", out of range [0, " + std::to_string(num_vertices) + ")");
      }
      mesh.triangles[i / 3][i % 3] = vertex;
    }
    return mesh;
  }

  // Exact integer index (Component() goes through float, which is not exact above 2^24).
  static uint32_t ReadIndex(const AccessorView& view, size_t i) {
    if (view.data == nullptr) return 0;
    const char* p = view.data + i * view.stride;
    switch (view.component_type) {
      case kComponentUnsignedByte: return static_cast<uint8_t>(*p);
      case kComponentUnsignedShort: return LoadLittleEndian<uint16_t>(p);
      default: return LoadLittleEndian<uint32_t>(p);
    }
  }

  std::string_view bytes_;
  const std::string& name_;
  JsonValue json_;
  std::string_view bin_;
  bool has_bin_ = false;
};

}  // namespace

Result<Mesh> DecodeGlb(std::string_view bytes, const std::string& name_for_errors) {
  return GlbDecoder(bytes, name_for_errors).Decode();
}

Result<Mesh> ReadGlb(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  return DecodeGlb(bytes, path);
}

}  // namespace reconar
