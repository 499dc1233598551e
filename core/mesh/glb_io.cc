#include "core/mesh/glb_io.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <utility>
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
constexpr int kFilterLinear = 9729;
constexpr int kFilterLinearMipmapLinear = 9987;
constexpr int kWrapClampToEdge = 33071;

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

// One node of a scene to write; an empty name is left out.
struct SceneElement {
  std::string_view name;
  const Mesh* mesh;
};

// What the JSON says about a mesh whose data is in the BIN chunk.
struct MeshLayout {
  Eigen::Vector3f min;  // of the positions
  Eigen::Vector3f max;
  bool short_indices;
};

// Appends the mesh's positions, normals, colours and indices to `bin`, one buffer view each, each
// view 4-byte aligned.
Result<MeshLayout> AppendMeshData(const Mesh& mesh, std::string* bin, std::vector<BufferViewSpec>* views) {
  RECONAR_RETURN_IF_ERROR(ValidateMesh(mesh));
  if (mesh.positions.empty()) return InvalidArgument("mesh: no vertices (glTF accessors need at least one)");
  RECONAR_RETURN_IF_ERROR(CheckFinite(mesh.positions, "position"));
  RECONAR_RETURN_IF_ERROR(CheckFinite(mesh.normals, "normal"));
  for (size_t i = 0; i < mesh.texcoords.size(); ++i) {
    if (!mesh.texcoords[i].allFinite()) {
      return InvalidArgument("mesh: texture coordinate " + std::to_string(i) + " is not finite");
    }
  }
  const size_t num_vertices = mesh.positions.size();
  // The largest value of the index type is reserved (primitive restart), so uint32 indices reach
  // 2^32 - 2 and uint16 indices 65534.
  if (num_vertices > std::numeric_limits<uint32_t>::max()) {
    return InvalidArgument("mesh: " + std::to_string(num_vertices) + " vertices exceed glTF's uint32 indices");
  }
  MeshLayout layout{mesh.positions[0], mesh.positions[0], num_vertices <= std::numeric_limits<uint16_t>::max()};

  const auto begin_view = [&] { return bin->size(); };
  const auto end_view = [&](size_t offset, int target) {
    views->push_back({offset, bin->size() - offset, target});
    bin->resize(Align4(bin->size()), '\0');
  };
  size_t offset = begin_view();
  for (const Eigen::Vector3f& p : mesh.positions) {
    for (int axis = 0; axis < 3; ++axis) AppendLittleEndian(bin, p[axis]);
    layout.min = layout.min.cwiseMin(p);
    layout.max = layout.max.cwiseMax(p);
  }
  end_view(offset, kTargetArrayBuffer);
  if (!mesh.normals.empty()) {
    offset = begin_view();
    for (const Eigen::Vector3f& n : mesh.normals) {
      for (int axis = 0; axis < 3; ++axis) AppendLittleEndian(bin, n[axis]);
    }
    end_view(offset, kTargetArrayBuffer);
  }
  if (!mesh.colors.empty()) {
    offset = begin_view();
    for (const std::array<uint8_t, 4>& c : mesh.colors) bin->append(reinterpret_cast<const char*>(c.data()), 4);
    end_view(offset, kTargetArrayBuffer);
  }
  if (!mesh.texcoords.empty()) {
    offset = begin_view();
    for (const Eigen::Vector2f& uv : mesh.texcoords) {
      AppendLittleEndian(bin, uv.x());
      AppendLittleEndian(bin, uv.y());
    }
    end_view(offset, kTargetArrayBuffer);
  }
  if (!mesh.triangles.empty()) {
    offset = begin_view();
    for (const std::array<uint32_t, 3>& triangle : mesh.triangles) {
      for (const uint32_t index : triangle) {
        if (layout.short_indices) {
          AppendLittleEndian(bin, static_cast<uint16_t>(index));
        } else {
          AppendLittleEndian(bin, index);
        }
      }
    }
    end_view(offset, kTargetElementArrayBuffer);
  }
  return layout;
}

// One primitive of `mesh`; its accessors are numbered from *accessor on. `material`: its
// material's index, or -1 for none.
void WritePrimitiveJson(JsonWriter* json, const Mesh& mesh, int material, int* accessor) {
  json->BeginObject();
  json->Key("attributes").BeginObject().Key("POSITION").Int((*accessor)++);
  if (!mesh.normals.empty()) json->Key("NORMAL").Int((*accessor)++);
  if (!mesh.colors.empty()) json->Key("COLOR_0").Int((*accessor)++);
  if (!mesh.texcoords.empty()) json->Key("TEXCOORD_0").Int((*accessor)++);
  json->EndObject();
  if (!mesh.triangles.empty()) json->Key("indices").Int((*accessor)++);
  if (material >= 0) json->Key("material").Int(material);
  json->Key("mode").Int(mesh.triangles.empty() ? kModePoints : kModeTriangles);
  json->EndObject();
}

// The accessors of WritePrimitiveJson's primitive, on the buffer views numbered from *view on.
void WriteAccessorsJson(JsonWriter* json, const Mesh& mesh, const MeshLayout& layout, int* view) {
  const size_t num_vertices = mesh.positions.size();
  WriteAccessor(json, (*view)++, kComponentFloat, num_vertices, "VEC3");
  json->Key("min").BeginArray().Double(layout.min.x()).Double(layout.min.y()).Double(layout.min.z()).EndArray();
  json->Key("max").BeginArray().Double(layout.max.x()).Double(layout.max.y()).Double(layout.max.z()).EndArray();
  json->EndObject();
  if (!mesh.normals.empty()) {
    WriteAccessor(json, (*view)++, kComponentFloat, num_vertices, "VEC3");
    json->EndObject();
  }
  if (!mesh.colors.empty()) {
    WriteAccessor(json, (*view)++, kComponentUnsignedByte, num_vertices, "VEC4");
    json->Key("normalized").Bool(true).EndObject();
  }
  if (!mesh.texcoords.empty()) {
    WriteAccessor(json, (*view)++, kComponentFloat, num_vertices, "VEC2");
    json->EndObject();
  }
  if (!mesh.triangles.empty()) {
    WriteAccessor(json, (*view)++, layout.short_indices ? kComponentUnsignedShort : kComponentUnsignedInt,
                  3 * mesh.triangles.size(), "SCALAR");
    json->EndObject();
  }
}

// `base_color_pngs`: empty, or one PNG per element: then the elements are the primitives of one
// mesh (of one unnamed node), element i with material i, whose base colour texture is PNG i.
Result<std::string> EncodeScene(const std::vector<SceneElement>& elements,
                                const std::vector<std::string_view>& base_color_pngs = {}) {
  if (elements.empty()) return InvalidArgument("glTF scene: no meshes to write");
  const bool textured = !base_color_pngs.empty();
  if (textured && base_color_pngs.size() != elements.size()) {
    return InvalidArgument("glTF scene: " + std::to_string(base_color_pngs.size()) + " textures for " +
                           std::to_string(elements.size()) + " primitives");
  }
  // BIN chunk: each mesh's positions, normals, colours, indices.
  std::string bin;
  std::vector<BufferViewSpec> views;
  std::vector<MeshLayout> layouts;
  for (size_t i = 0; i < elements.size(); ++i) {
    const std::string element = (textured ? "page " : "element ") + std::to_string(i) +
                                (elements[i].name.empty() ? "" : " '" + std::string(elements[i].name) + "'");
    // Our JSON reader, like the glTF specification, accepts UTF-8 strings only.
    if (!ParseJson(JsonQuote(std::string(elements[i].name)), element).ok()) {
      return InvalidArgument(element + ": the name is not valid UTF-8");
    }
    Result<MeshLayout> layout = AppendMeshData(*elements[i].mesh, &bin, &views);
    if (!layout.ok()) return elements.size() == 1 ? layout.status() : layout.status().WithContext(element);
    layouts.push_back(*layout);
  }
  const size_t first_image_view = views.size();
  for (const std::string_view png : base_color_pngs) {
    const size_t offset = bin.size();
    bin.append(png.data(), png.size());
    views.push_back({offset, png.size(), 0});
    bin.resize(Align4(bin.size()), '\0');
  }

  JsonWriter json;
  json.BeginObject();
  json.Key("asset").BeginObject().Key("version").String("2.0").Key("generator").String("reconar").EndObject();
  json.Key("scene").Int(0);
  const size_t num_nodes = textured ? 1 : elements.size();
  json.Key("scenes").BeginArray().BeginObject().Key("nodes").BeginArray();
  for (size_t i = 0; i < num_nodes; ++i) json.Int(static_cast<long long>(i));
  json.EndArray().EndObject().EndArray();
  json.Key("nodes").BeginArray();
  for (size_t i = 0; i < num_nodes; ++i) {
    json.BeginObject();
    if (!textured && !elements[i].name.empty()) json.Key("name").String(std::string(elements[i].name));
    json.Key("mesh").Int(static_cast<long long>(i)).EndObject();
  }
  json.EndArray();
  int accessor = 0;
  json.Key("meshes").BeginArray();
  if (textured) json.BeginObject().Key("primitives").BeginArray();
  for (size_t i = 0; i < elements.size(); ++i) {
    if (!textured) json.BeginObject().Key("primitives").BeginArray();
    WritePrimitiveJson(&json, *elements[i].mesh, textured ? static_cast<int>(i) : -1, &accessor);
    if (!textured) json.EndArray().EndObject();
  }
  if (textured) json.EndArray().EndObject();
  json.EndArray();
  if (textured) {
    // Photographs are sRGB, as glTF's base colour texture is; metallic 0, rough 1: a matte surface.
    json.Key("materials").BeginArray();
    for (size_t i = 0; i < elements.size(); ++i) {
      json.BeginObject().Key("pbrMetallicRoughness").BeginObject();
      json.Key("baseColorTexture").BeginObject().Key("index").Int(static_cast<long long>(i)).EndObject();
      json.Key("metallicFactor").Int(0).Key("roughnessFactor").Int(1);
      json.EndObject().EndObject();
    }
    json.EndArray();
    json.Key("textures").BeginArray();
    for (size_t i = 0; i < elements.size(); ++i) {
      json.BeginObject().Key("sampler").Int(0).Key("source").Int(static_cast<long long>(i)).EndObject();
    }
    json.EndArray();
    json.Key("samplers").BeginArray().BeginObject();
    json.Key("magFilter").Int(kFilterLinear).Key("minFilter").Int(kFilterLinearMipmapLinear);
    json.Key("wrapS").Int(kWrapClampToEdge).Key("wrapT").Int(kWrapClampToEdge);
    json.EndObject().EndArray();
    json.Key("images").BeginArray();
    for (size_t i = 0; i < elements.size(); ++i) {
      json.BeginObject().Key("bufferView").Int(static_cast<long long>(first_image_view + i));
      json.Key("mimeType").String("image/png").EndObject();
    }
    json.EndArray();
  }
  int view = 0;
  json.Key("accessors").BeginArray();
  for (size_t i = 0; i < elements.size(); ++i) WriteAccessorsJson(&json, *elements[i].mesh, layouts[i], &view);
  json.EndArray();

  json.Key("bufferViews").BeginArray();
  for (const BufferViewSpec& spec : views) {
    json.BeginObject()
        .Key("buffer").Int(0)
        .Key("byteOffset").Int(static_cast<long long>(spec.offset))
        .Key("byteLength").Int(static_cast<long long>(spec.length));
    if (spec.target != 0) json.Key("target").Int(spec.target);  // an image's view has none
    json.EndObject();
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

Status WriteEncodedGlb(const std::string& path, const Result<std::string>& glb) {
  if (!glb.ok()) return glb.status().WithContext(path);
  return WriteFileAtomically(path, *glb);
}

}  // namespace

Result<std::string> EncodeGlb(const Mesh& mesh) { return EncodeScene({{std::string_view(), &mesh}}); }

Status WriteGlb(const std::string& path, const Mesh& mesh) { return WriteEncodedGlb(path, EncodeGlb(mesh)); }

bool IsPngSignature(std::string_view bytes) {
  return bytes.substr(0, 8) == std::string_view("\x89PNG\r\n\x1a\n", 8);
}

Result<std::string> EncodeTexturedGlb(const Mesh& mesh, const std::vector<EncodedTexturePage>& pages) {
  if (mesh.texcoords.empty()) return InvalidArgument("mesh: no texture coordinates for the texture");
  RECONAR_RETURN_IF_ERROR(ValidateTexturePages(pages, mesh.triangles.size()));
  std::vector<std::string_view> pngs;
  for (size_t k = 0; k < pages.size(); ++k) {
    if (!IsPngSignature(pages[k].image)) {
      return InvalidArgument("mesh: the base colour texture" + (pages.size() > 1 ? " page " + std::to_string(k) : "") +
                             " is not a PNG");
    }
    pngs.push_back(pages[k].image);
  }
  if (pages.size() == 1) return EncodeScene({{std::string_view(), &mesh}}, pngs);
  RECONAR_RETURN_IF_ERROR(ValidateMesh(mesh));
  std::vector<Mesh> parts;
  for (size_t k = 0; k < pages.size(); ++k) {
    std::vector<size_t> triangles(PageTrianglesEnd(pages, k, mesh.triangles.size()) - pages[k].first_triangle);
    std::iota(triangles.begin(), triangles.end(), pages[k].first_triangle);
    parts.push_back(SubMesh(mesh, triangles));
  }
  std::vector<SceneElement> elements;
  for (const Mesh& part : parts) elements.push_back({std::string_view(), &part});
  return EncodeScene(elements, pngs);
}

Status WriteTexturedGlb(const std::string& path, const Mesh& mesh, const std::vector<EncodedTexturePage>& pages) {
  return WriteEncodedGlb(path, EncodeTexturedGlb(mesh, pages));
}

Result<std::string> EncodeGlbScene(const std::vector<NamedMesh>& meshes) {
  std::vector<SceneElement> elements;
  elements.reserve(meshes.size());
  for (const NamedMesh& named : meshes) elements.push_back({named.name, &named.mesh});
  return EncodeScene(elements);
}

Status WriteGlbScene(const std::string& path, const std::vector<NamedMesh>& meshes) {
  return WriteEncodedGlb(path, EncodeGlbScene(meshes));
}

// ---------------------------------------------------------------------------------------------
// Reading.

namespace {

constexpr int kMaxNodeDepth = 64;
constexpr size_t kMaxSceneVertices = size_t{1} << 28;
// Images' data: URIs are cached with the buffers', under their index plus this.
constexpr size_t kImageUriKey = size_t{1} << 40;

// The 6-bit value of a base64 character (RFC 4648, section 4), -1 for any other character.
int Base64Value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

// RFC 4648 base64 with its padding; nullopt for a length that is not a multiple of 4, a character
// outside the alphabet (white space included) or a '=' anywhere but in the last two places.
std::optional<std::string> DecodeBase64(std::string_view text) {
  if (text.size() % 4 != 0) return std::nullopt;
  std::string bytes;
  bytes.reserve(text.size() / 4 * 3);
  for (size_t group = 0; group < text.size(); group += 4) {
    const bool last = group + 4 == text.size();
    const int padding = !last ? 0 : text[group + 3] != '=' ? 0 : text[group + 2] != '=' ? 1 : 2;
    uint32_t bits = 0;
    for (int i = 0; i < 4; ++i) {
      const int value = i >= 4 - padding ? 0 : Base64Value(text[group + i]);
      if (value < 0) return std::nullopt;
      bits = (bits << 6) | static_cast<uint32_t>(value);
    }
    bytes.push_back(static_cast<char>(bits >> 16));
    if (padding < 2) bytes.push_back(static_cast<char>((bits >> 8) & 0xFF));
    if (padding < 1) bytes.push_back(static_cast<char>(bits & 0xFF));
  }
  return bytes;
}

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// A URI's "%XX" escapes decoded (RFC 3986, section 2.1); nullopt for a malformed escape.
std::optional<std::string> PercentDecode(std::string_view text) {
  std::string decoded;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      decoded.push_back(text[i]);
      continue;
    }
    const int high = i + 2 < text.size() ? HexValue(text[i + 1]) : -1;
    const int low = i + 2 < text.size() ? HexValue(text[i + 2]) : -1;
    if (high < 0 || low < 0) return std::nullopt;
    decoded.push_back(static_cast<char>(high * 16 + low));
    i += 2;
  }
  return decoded;
}

class GlbDecoder {
 public:
  // `base_directory`: where the files that buffers' uris name are read from; without one, a
  // buffer with a uri is kUnsupported.
  GlbDecoder(std::string_view bytes, const std::string& name, std::optional<std::string> base_directory = {})
      : bytes_(bytes), name_(name), base_directory_(std::move(base_directory)) {}

  Result<Mesh> Decode() {
    RECONAR_ASSIGN_OR_RETURN(TexturedGlb textured, DecodeTextured(false));
    return std::move(textured.mesh);
  }

  // With `with_texture`, the texture coordinates and the base colour images are kept.
  Result<TexturedGlb> DecodeTextured(bool with_texture) {
    RECONAR_RETURN_IF_ERROR(ReadContainer());
    RECONAR_RETURN_IF_ERROR(CheckAssetAndExtensions());
    const JsonValue* primitive = nullptr;
    RECONAR_RETURN_IF_ERROR(FindFirstPrimitive(&primitive));
    read_texcoords_ = with_texture;
    TexturedGlb textured;
    RECONAR_ASSIGN_OR_RETURN(textured.mesh, ReadPrimitive(*primitive, "meshes[0].primitives[0]"));
    if (!with_texture) return textured;
    int64_t image_index = -1;
    std::string image;
    RECONAR_RETURN_IF_ERROR(ReadBaseColorImage(*primitive, "meshes[0].primitives[0]", &image_index, &image));
    if (image.empty()) {
      textured.mesh.texcoords.clear();
      return textured;
    }
    textured.pages.push_back({0, std::move(image)});
    // The other TRIANGLES primitives, when every one has a base colour image; else the first alone.
    const JsonValue& primitives = *(*RootArray("meshes"))[0].Find("primitives");
    Mesh& mesh = textured.mesh;
    const std::array<size_t, 5> first_sizes = {mesh.positions.size(), mesh.normals.size(), mesh.colors.size(),
                                               mesh.texcoords.size(), mesh.triangles.size()};
    auto first_primitive_alone = [&]() {
      mesh.positions.resize(first_sizes[0]);
      mesh.normals.resize(first_sizes[1]);
      mesh.colors.resize(first_sizes[2]);
      mesh.texcoords.resize(first_sizes[3]);
      mesh.triangles.resize(first_sizes[4]);
      textured.pages.resize(1);
      return std::move(textured);
    };
    for (size_t p = 1; p < primitives.size(); ++p) {
      const std::string where = "meshes[0].primitives[" + std::to_string(p) + "]";
      if (!primitives[p].is_object()) return Corrupt(where + " is not an object");
      int64_t mode = kModeTriangles, index = -1;
      RECONAR_RETURN_IF_ERROR(GetIndex(primitives[p], "mode", where, &mode, kModeTriangles));
      if (mode != kModeTriangles) continue;
      RECONAR_RETURN_IF_ERROR(ReadBaseColorImage(primitives[p], where, &index, &image));
      if (image.empty()) return first_primitive_alone();
      RECONAR_ASSIGN_OR_RETURN(const Mesh part, ReadPrimitive(primitives[p], where));
      if (part.triangles.empty()) continue;
      if (part.texcoords.size() != part.positions.size()) {
        return Unsupported(where + " has no TEXCOORD_0 for its texture");
      }
      if (part.positions.size() > kMaxSceneVertices - mesh.positions.size()) {
        return FileError(StatusCode::kResourceExhausted, name_,
                         "more than " + std::to_string(kMaxSceneVertices) + " vertices in the mesh");
      }
      if (mesh.normals.empty() != part.normals.empty() || mesh.colors.empty() != part.colors.empty()) {
        return Unsupported(where + " has other vertex attributes than meshes[0].primitives[0]");
      }
      if (index != image_index) textured.pages.push_back({mesh.triangles.size(), std::move(image)});
      image_index = index;
      const uint32_t first_vertex = static_cast<uint32_t>(mesh.positions.size());
      mesh.positions.insert(mesh.positions.end(), part.positions.begin(), part.positions.end());
      mesh.normals.insert(mesh.normals.end(), part.normals.begin(), part.normals.end());
      mesh.colors.insert(mesh.colors.end(), part.colors.begin(), part.colors.end());
      mesh.texcoords.insert(mesh.texcoords.end(), part.texcoords.begin(), part.texcoords.end());
      for (const std::array<uint32_t, 3>& triangle : part.triangles) {
        mesh.triangles.push_back({triangle[0] + first_vertex, triangle[1] + first_vertex, triangle[2] + first_vertex});
      }
    }
    return textured;
  }

  // A .glb, or a .gltf JSON text.
  Result<std::vector<NamedMesh>> DecodeScene() {
    if (bytes_.size() >= 4 && LoadLittleEndian<uint32_t>(bytes_.data()) == kGlbMagic) {
      RECONAR_RETURN_IF_ERROR(ReadContainer());
    } else {
      RECONAR_RETURN_IF_ERROR(ParseGltfJson(bytes_, name_, "the glTF JSON"));
    }
    RECONAR_RETURN_IF_ERROR(CheckAssetAndExtensions());
    std::vector<int64_t> parents;
    RECONAR_RETURN_IF_ERROR(ReadNodeHierarchy(&parents));
    std::vector<size_t> roots;
    RECONAR_RETURN_IF_ERROR(GetSceneRoots(parents, &roots));
    std::vector<NamedMesh> meshes;
    for (const size_t root : roots) {
      RECONAR_RETURN_IF_ERROR(AddNodeMeshes(root, Eigen::Affine3d::Identity(), &meshes));
    }
    if (meshes.empty()) return Corrupt("no triangle mesh in the scene");
    return meshes;
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
        RECONAR_RETURN_IF_ERROR(ParseGltfJson(data, name_ + " (JSON chunk)", "the JSON chunk"));
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

  // `json_name` prefixes the parser's messages; `what` names the JSON in ours.
  Status ParseGltfJson(std::string_view text, const std::string& json_name, const std::string& what) {
    Result<JsonValue> json = ParseJson(text, json_name);
    if (!json.ok()) return json.status();
    json_ = std::move(json).value();
    if (!json_.is_object()) return Corrupt(what + " is not an object");
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
    std::string_view data = bin_;
    const char* source = "the BIN chunk";
    if (const JsonValue* uri = entry.Find("uri")) {
      if (!base_directory_.has_value()) return Unsupported(where + " has a uri (external or data: URI buffers)");
      RECONAR_RETURN_IF_ERROR(LoadUriBuffer(static_cast<size_t>(index), *uri, where + ".uri", &data));
      source = "the data of its uri";
    } else {
      if (index != 0) return Corrupt(where + " has no uri, but only buffers[0] can be the GLB's BIN chunk");
      if (!has_bin_) return Corrupt("buffers[0] refers to the BIN chunk, but the file has none");
    }
    int64_t length = 0;
    RECONAR_RETURN_IF_ERROR(GetIndex(entry, "byteLength", where, &length));
    if (static_cast<uint64_t>(length) > data.size()) {
      return Corrupt(where + ".byteLength " + std::to_string(length) + " exceeds " + source + " (" +
                     std::to_string(data.size()) + " bytes)");
    }
    *buffer = data.substr(0, static_cast<size_t>(length));
    return Status::Ok();
  }

  // The bytes of a base64 data: URI or of the file a relative URI names; each buffer is loaded once.
  Status LoadUriBuffer(size_t index, const JsonValue& uri, const std::string& where, std::string_view* data) const {
    if (const auto loaded = uri_buffers_.find(index); loaded != uri_buffers_.end()) {
      *data = loaded->second;
      return Status::Ok();
    }
    if (!uri.is_string()) return Corrupt(where + " is not a string");
    const std::string& text = uri.string();
    std::string bytes;
    if (text.rfind("data:", 0) == 0) {
      const size_t comma = text.find(',');
      const std::string_view base64 = ";base64";
      if (comma == std::string::npos || comma < 5 + base64.size() ||
          std::string_view(text).substr(comma - base64.size(), base64.size()) != base64) {
        return Unsupported(where + " is a data: URI without base64");
      }
      std::optional<std::string> decoded = DecodeBase64(std::string_view(text).substr(comma + 1));
      if (!decoded.has_value()) return Corrupt(where + " is a data: URI with invalid base64");
      bytes = std::move(*decoded);
    } else {
      std::string relative_path;
      RECONAR_RETURN_IF_ERROR(RelativePathOfUri(text, where, &relative_path));
      const std::string path = base_directory_->empty() ? relative_path : *base_directory_ + "/" + relative_path;
      Result<std::string> file = ReadFileToString(path);
      if (!file.ok()) return file.status().WithContext(name_ + ": " + where);
      bytes = std::move(file).value();
    }
    *data = uri_buffers_.emplace(index, std::move(bytes)).first->second;
    return Status::Ok();
  }

  // The file a URI names, relative to the base directory: no scheme, not absolute, no "..".
  Status RelativePathOfUri(const std::string& uri, const std::string& where, std::string* relative_path) const {
    const std::string quoted = where + " \"" + uri + "\"";
    const size_t colon = uri.find(':');
    if (colon != std::string::npos && colon < uri.find('/')) {
      return Unsupported(quoted + ": only data: URIs and relative file names are read");
    }
    std::optional<std::string> decoded = PercentDecode(uri);
    if (!decoded.has_value()) return Corrupt(quoted + " has a malformed percent escape");
    if (decoded->empty() || decoded->find('\0') != std::string::npos) return Corrupt(quoted + " does not name a file");
    if (decoded->front() == '/' || decoded->front() == '\\') return Corrupt(quoted + " is an absolute path");
    size_t segment_start = 0;
    while (segment_start <= decoded->size()) {
      size_t segment_end = decoded->find_first_of("/\\", segment_start);
      if (segment_end == std::string::npos) segment_end = decoded->size();
      if (decoded->compare(segment_start, segment_end - segment_start, "..") == 0) {
        return Corrupt(quoted + " leaves the directory of the file (\"..\")");
      }
      segment_start = segment_end + 1;
    }
    *relative_path = std::move(*decoded);
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

  // Element `index` of the root array `key`, which must be an object.
  Status GetRootObject(const char* key, int64_t index, const JsonValue** element) const {
    const JsonValue* array = RootArray(key);
    if (array == nullptr || index < 0 || index >= static_cast<int64_t>(array->size()) ||
        !(*array)[static_cast<size_t>(index)].is_object()) {
      return Corrupt(std::string(key) + "[" + std::to_string(index) + "] missing");
    }
    *element = &(*array)[static_cast<size_t>(index)];
    return Status::Ok();
  }

  Status ReadTexcoords(const AccessorView& view, std::vector<Eigen::Vector2f>* out) const {
    if (view.components != 2) return Corrupt(view.where + " must be VEC2");
    const bool valid_type = view.component_type == kComponentFloat ||
                            (view.normalized && (view.component_type == kComponentUnsignedByte ||
                                                 view.component_type == kComponentUnsignedShort));
    if (!valid_type) return Corrupt(view.where + ": TEXCOORD_0 must be float or normalized unsigned byte/short");
    out->resize(view.count);
    for (size_t i = 0; i < view.count; ++i) {
      (*out)[i] = Eigen::Vector2f(Component(view, i, 0), Component(view, i, 1));
      if (!(*out)[i].allFinite()) return Corrupt(view.where + ": texture coordinate " + std::to_string(i) + " is not finite");
    }
    return Status::Ok();
  }

  // The image of the primitive's material's base colour texture, when it has one: from a buffer
  // view, or a data: URI.
  // The image of the primitive's material's base colour texture, and its index; empty when it has none.
  Status ReadBaseColorImage(const JsonValue& primitive, const std::string& where, int64_t* image_index_out,
                            std::string* image_bytes) const {
    image_bytes->clear();
    int64_t material_index = -1, texture_index = -1, image_index = -1;
    RECONAR_RETURN_IF_ERROR(GetIndex(primitive, "material", where, &material_index, -1));
    if (material_index < 0) return Status::Ok();
    const JsonValue* material = nullptr;
    const std::string material_where = "materials[" + std::to_string(material_index) + "]";
    RECONAR_RETURN_IF_ERROR(GetRootObject("materials", material_index, &material));
    const JsonValue* pbr = material->Find("pbrMetallicRoughness");
    const JsonValue* base_color = pbr != nullptr && pbr->is_object() ? pbr->Find("baseColorTexture") : nullptr;
    if (base_color == nullptr || !base_color->is_object()) return Status::Ok();
    const std::string base_where = material_where + ".pbrMetallicRoughness.baseColorTexture";
    RECONAR_RETURN_IF_ERROR(GetIndex(*base_color, "index", base_where, &texture_index));
    int64_t texcoord_set = 0;
    RECONAR_RETURN_IF_ERROR(GetIndex(*base_color, "texCoord", base_where, &texcoord_set, 0));
    if (texcoord_set != 0) return Unsupported(base_where + " uses TEXCOORD_" + std::to_string(texcoord_set));
    const JsonValue* texture = nullptr;
    RECONAR_RETURN_IF_ERROR(GetRootObject("textures", texture_index, &texture));
    if (texture->Find("source") == nullptr) return Status::Ok();  // an extension's image only
    RECONAR_RETURN_IF_ERROR(
        GetIndex(*texture, "source", "textures[" + std::to_string(texture_index) + "]", &image_index));
    const JsonValue* image_object = nullptr;
    RECONAR_RETURN_IF_ERROR(GetRootObject("images", image_index, &image_object));
    *image_index_out = image_index;
    const JsonValue& image = *image_object;
    const std::string image_where = "images[" + std::to_string(image_index) + "]";
    if (const JsonValue* uri = image.Find("uri")) {
      if (!uri->is_string() || uri->string().rfind("data:", 0) != 0) {
        return Unsupported(image_where + " is an external file (only embedded images are read)");
      }
      std::string_view data;
      RECONAR_RETURN_IF_ERROR(LoadUriBuffer(kImageUriKey + static_cast<size_t>(image_index), *uri,
                                            image_where + ".uri", &data));
      *image_bytes = std::string(data);
      return Status::Ok();
    }
    int64_t view_index = 0, buffer_index = 0, view_offset = 0, view_length = 0;
    RECONAR_RETURN_IF_ERROR(GetIndex(image, "bufferView", image_where, &view_index));
    const JsonValue* buffer_view_object = nullptr;
    RECONAR_RETURN_IF_ERROR(GetRootObject("bufferViews", view_index, &buffer_view_object));
    const JsonValue& buffer_view = *buffer_view_object;
    const std::string view_where = "bufferViews[" + std::to_string(view_index) + "]";
    RECONAR_RETURN_IF_ERROR(GetIndex(buffer_view, "buffer", view_where, &buffer_index));
    RECONAR_RETURN_IF_ERROR(GetIndex(buffer_view, "byteOffset", view_where, &view_offset, 0));
    RECONAR_RETURN_IF_ERROR(GetIndex(buffer_view, "byteLength", view_where, &view_length));
    std::string_view buffer;
    RECONAR_RETURN_IF_ERROR(GetBuffer(buffer_index, &buffer));
    if (static_cast<uint64_t>(view_offset) > buffer.size() ||
        static_cast<uint64_t>(view_length) > buffer.size() - static_cast<uint64_t>(view_offset)) {
      return Corrupt(view_where + " lies outside buffers[" + std::to_string(buffer_index) + "]");
    }
    *image_bytes = std::string(buffer.substr(static_cast<size_t>(view_offset), static_cast<size_t>(view_length)));
    return Status::Ok();
  }

  // `where` names the primitive ("meshes[0].primitives[0]").
  Result<Mesh> ReadPrimitive(const JsonValue& primitive, const std::string& where) const {
    if (const JsonValue* extensions = primitive.Find("extensions")) {
      if (extensions->Find("KHR_draco_mesh_compression") != nullptr) {
        return Unsupported(where + " is draco-compressed (KHR_draco_mesh_compression)");
      }
    }
    int64_t mode = kModeTriangles;
    RECONAR_RETURN_IF_ERROR(GetIndex(primitive, "mode", where, &mode, kModeTriangles));
    if (mode != kModeTriangles && mode != kModePoints) {
      return Unsupported("primitive mode " + std::to_string(mode) + " (only TRIANGLES and POINTS are read)");
    }
    const JsonValue* attributes = primitive.Find("attributes");
    const std::string attributes_where = where + ".attributes";
    if (attributes == nullptr || !attributes->is_object()) return Corrupt(attributes_where + " missing");

    Mesh mesh;
    int64_t index = 0;
    RECONAR_RETURN_IF_ERROR(GetIndex(*attributes, "POSITION", attributes_where, &index));
    AccessorView view;
    RECONAR_RETURN_IF_ERROR(GetAccessor(index, &view));
    RECONAR_RETURN_IF_ERROR(ReadVectors(view, &mesh.positions));
    const size_t num_vertices = mesh.positions.size();
    if (attributes->Find("NORMAL") != nullptr) {
      RECONAR_RETURN_IF_ERROR(GetIndex(*attributes, "NORMAL", attributes_where, &index));
      RECONAR_RETURN_IF_ERROR(GetAccessor(index, &view));
      if (view.count != num_vertices) return Corrupt(view.where + ": NORMAL count differs from POSITION count");
      RECONAR_RETURN_IF_ERROR(ReadVectors(view, &mesh.normals));
    }
    if (attributes->Find("COLOR_0") != nullptr) {
      RECONAR_RETURN_IF_ERROR(GetIndex(*attributes, "COLOR_0", attributes_where, &index));
      RECONAR_RETURN_IF_ERROR(GetAccessor(index, &view));
      if (view.count != num_vertices) return Corrupt(view.where + ": COLOR_0 count differs from POSITION count");
      RECONAR_RETURN_IF_ERROR(ReadColors(view, &mesh.colors));
    }
    if (read_texcoords_ && attributes->Find("TEXCOORD_0") != nullptr) {
      RECONAR_RETURN_IF_ERROR(GetIndex(*attributes, "TEXCOORD_0", attributes_where, &index));
      RECONAR_RETURN_IF_ERROR(GetAccessor(index, &view));
      if (view.count != num_vertices) return Corrupt(view.where + ": TEXCOORD_0 count differs from POSITION count");
      RECONAR_RETURN_IF_ERROR(ReadTexcoords(view, &mesh.texcoords));
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
    RECONAR_RETURN_IF_ERROR(GetIndex(primitive, "indices", where, &index));
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

  // Reads every node's children into node_children_ and checks that the nodes form trees: one
  // parent per node, no cycle, at most kMaxNodeDepth levels. `parents[n]` is -1 for a root.
  Status ReadNodeHierarchy(std::vector<int64_t>* parents) {
    const JsonValue* nodes = RootArray("nodes");
    const size_t num_nodes = nodes == nullptr ? 0 : nodes->size();
    node_children_.assign(num_nodes, {});
    parents->assign(num_nodes, -1);
    for (size_t n = 0; n < num_nodes; ++n) {
      const std::string where = "nodes[" + std::to_string(n) + "]";
      if (!(*nodes)[n].is_object()) return Corrupt(where + " is not an object");
      const JsonValue* children = (*nodes)[n].Find("children");
      if (children == nullptr) continue;
      if (!children->is_array()) return Corrupt(where + ".children is not an array");
      for (size_t i = 0; i < children->size(); ++i) {
        const std::string entry = where + ".children[" + std::to_string(i) + "]";
        size_t child = 0;
        RECONAR_RETURN_IF_ERROR(GetNodeIndex((*children)[i], entry, num_nodes, &child));
        if ((*parents)[child] >= 0) {
          return Corrupt(entry + ": nodes[" + std::to_string(child) + "] is already a child of nodes[" +
                         std::to_string((*parents)[child]) + "]");
        }
        (*parents)[child] = static_cast<int64_t>(n);
        node_children_[n].push_back(child);
      }
    }
    std::vector<bool> reached(num_nodes, false);
    for (size_t n = 0; n < num_nodes; ++n) {
      if ((*parents)[n] < 0) RECONAR_RETURN_IF_ERROR(MarkSubtree(n, 1, &reached));
    }
    for (size_t n = 0; n < num_nodes; ++n) {
      if (reached[n]) continue;
      // With one parent per node, a node that no root reaches hangs from a cycle: climbing
      // num_nodes parents from it ends on the cycle.
      int64_t on_cycle = static_cast<int64_t>(n);
      for (size_t step = 0; step < num_nodes; ++step) on_cycle = (*parents)[static_cast<size_t>(on_cycle)];
      return Corrupt("nodes[" + std::to_string(on_cycle) + "] is its own ancestor (a cycle of children)");
    }
    return Status::Ok();
  }

  Status MarkSubtree(size_t node, int depth, std::vector<bool>* reached) const {
    if (depth > kMaxNodeDepth) {
      return Corrupt("nodes[" + std::to_string(node) + "] lies deeper than " + std::to_string(kMaxNodeDepth) +
                     " levels in the node hierarchy");
    }
    (*reached)[node] = true;
    for (const size_t child : node_children_[node]) RECONAR_RETURN_IF_ERROR(MarkSubtree(child, depth + 1, reached));
    return Status::Ok();
  }

  Status GetNodeIndex(const JsonValue& value, const std::string& where, size_t num_nodes, size_t* node) const {
    const std::optional<int64_t> index = value.AsInteger();
    if (!index.has_value() || *index < 0 || static_cast<uint64_t>(*index) >= num_nodes) {
      return Corrupt(where + " is not the index of a node");
    }
    *node = static_cast<size_t>(*index);
    return Status::Ok();
  }

  // The root nodes of the scene `scene` (else of scenes[0]), or every root node when the file has
  // neither `scene` nor `scenes`.
  Status GetSceneRoots(const std::vector<int64_t>& parents, std::vector<size_t>* roots) const {
    const JsonValue* scenes = RootArray("scenes");
    const JsonValue* default_scene = json_.Find("scene");
    if (default_scene == nullptr && scenes == nullptr) {
      for (size_t n = 0; n < parents.size(); ++n) {
        if (parents[n] < 0) roots->push_back(n);
      }
      return Status::Ok();
    }
    int64_t scene = 0;
    if (default_scene != nullptr) {
      const std::optional<int64_t> index = default_scene->AsInteger();
      if (!index.has_value() || *index < 0) return Corrupt("scene is not a non-negative integer");
      scene = *index;
    }
    const std::string where = "scenes[" + std::to_string(scene) + "]";
    if (scenes == nullptr || scene >= static_cast<int64_t>(scenes->size())) return Corrupt(where + " missing");
    const JsonValue* nodes = (*scenes)[static_cast<size_t>(scene)].Find("nodes");
    if (nodes == nullptr) return Status::Ok();
    if (!nodes->is_array()) return Corrupt(where + ".nodes is not an array");
    std::vector<bool> listed(parents.size(), false);
    for (size_t i = 0; i < nodes->size(); ++i) {
      const std::string entry = where + ".nodes[" + std::to_string(i) + "]";
      size_t node = 0;
      RECONAR_RETURN_IF_ERROR(GetNodeIndex((*nodes)[i], entry, parents.size(), &node));
      const std::string node_where = "nodes[" + std::to_string(node) + "]";
      if (parents[node] >= 0) return Corrupt(entry + ": " + node_where + " is not a root node");
      if (listed[node]) return Corrupt(entry + ": " + node_where + " is listed twice");
      listed[node] = true;
      roots->push_back(node);
    }
    return Status::Ok();
  }

  // `count` numbers of the array member `key`; `out` is left as it is when the member is absent.
  Status GetNumbers(const JsonValue& object, const char* key, const std::string& where, size_t count,
                    double* out) const {
    const JsonValue* value = object.Find(key);
    if (value == nullptr) return Status::Ok();
    const std::string message = where + "." + key + " is not an array of " + std::to_string(count) + " numbers";
    if (!value->is_array() || value->size() != count) return Corrupt(message);
    for (size_t i = 0; i < count; ++i) {
      if (!(*value)[i].is_number()) return Corrupt(message);
      out[i] = (*value)[i].number();
    }
    return Status::Ok();
  }

  // The node's transform from its frame to its parent's.
  Status GetLocalTransform(const JsonValue& node, const std::string& where, Eigen::Affine3d* local) const {
    *local = Eigen::Affine3d::Identity();
    if (node.Find("matrix") != nullptr) {
      Eigen::Matrix4d matrix;
      RECONAR_RETURN_IF_ERROR(GetNumbers(node, "matrix", where, 16, matrix.data()));  // both column-major
      if (matrix.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
        return Corrupt(where + ".matrix is not affine (its last row must be 0 0 0 1)");
      }
      local->matrix() = matrix;
      return Status::Ok();
    }
    Eigen::Vector3d translation = Eigen::Vector3d::Zero();
    Eigen::Vector4d rotation(0, 0, 0, 1);  // x y z w
    Eigen::Vector3d scale = Eigen::Vector3d::Ones();
    RECONAR_RETURN_IF_ERROR(GetNumbers(node, "translation", where, 3, translation.data()));
    RECONAR_RETURN_IF_ERROR(GetNumbers(node, "rotation", where, 4, rotation.data()));
    RECONAR_RETURN_IF_ERROR(GetNumbers(node, "scale", where, 3, scale.data()));
    const Eigen::Quaterniond quaternion(rotation[3], rotation[0], rotation[1], rotation[2]);
    if (!std::isnormal(quaternion.norm())) return Corrupt(where + ".rotation is not a rotation quaternion");
    local->linear() = quaternion.normalized().toRotationMatrix() * scale.asDiagonal();
    local->translation() = translation;
    return Status::Ok();
  }

  // Appends the meshes of nodes[node] and its descendants; `parent_transform` takes the parent's
  // frame to the scene's.
  Status AddNodeMeshes(size_t node, const Eigen::Affine3d& parent_transform, std::vector<NamedMesh>* meshes) {
    const JsonValue& json_node = (*RootArray("nodes"))[node];
    const std::string where = "nodes[" + std::to_string(node) + "]";
    Eigen::Affine3d local;
    RECONAR_RETURN_IF_ERROR(GetLocalTransform(json_node, where, &local));
    const Eigen::Affine3d transform = parent_transform * local;
    if (json_node.Find("mesh") != nullptr) {
      int64_t mesh_index = 0;
      RECONAR_RETURN_IF_ERROR(GetIndex(json_node, "mesh", where, &mesh_index));
      const JsonValue* json_meshes = RootArray("meshes");
      if (json_meshes == nullptr || mesh_index >= static_cast<int64_t>(json_meshes->size())) {
        return Corrupt(where + ".mesh: meshes[" + std::to_string(mesh_index) + "] missing");
      }
      const JsonValue& json_mesh = (*json_meshes)[static_cast<size_t>(mesh_index)];
      NamedMesh named;
      RECONAR_RETURN_IF_ERROR(ReadTriangleMesh(json_mesh, "meshes[" + std::to_string(mesh_index) + "]", &named.mesh));
      if (!named.mesh.triangles.empty()) {
        RECONAR_RETURN_IF_ERROR(TransformToScene(transform, where, &named.mesh));
        named.name = StringMember(json_node, "name");
        if (named.name.empty()) named.name = StringMember(json_mesh, "name");
        if (named.name.empty()) named.name = "node " + std::to_string(node);
        meshes->push_back(std::move(named));
      }
    }
    for (const size_t child : node_children_[node]) RECONAR_RETURN_IF_ERROR(AddNodeMeshes(child, transform, meshes));
    return Status::Ok();
  }

  static std::string StringMember(const JsonValue& object, const char* key) {
    const JsonValue* value = object.Find(key);
    return value != nullptr && value->is_string() ? value->string() : std::string();
  }

  // The mesh's TRIANGLES primitives as one mesh in its own frame; no triangles when it has none.
  Status ReadTriangleMesh(const JsonValue& json_mesh, const std::string& where, Mesh* mesh) {
    const JsonValue* primitives = json_mesh.Find("primitives");
    if (primitives == nullptr || !primitives->is_array()) return Corrupt(where + ".primitives missing");
    bool every_primitive_has_normals = true, every_primitive_has_colors = true;
    for (size_t p = 0; p < primitives->size(); ++p) {
      const JsonValue& primitive = (*primitives)[p];
      const std::string primitive_where = where + ".primitives[" + std::to_string(p) + "]";
      if (!primitive.is_object()) return Corrupt(primitive_where + " is not an object");
      int64_t mode = kModeTriangles;
      RECONAR_RETURN_IF_ERROR(GetIndex(primitive, "mode", primitive_where, &mode, kModeTriangles));
      if (mode != kModeTriangles) continue;
      RECONAR_ASSIGN_OR_RETURN(const Mesh part, ReadPrimitive(primitive, primitive_where));
      if (part.positions.size() > kMaxSceneVertices - scene_vertices_) {
        return FileError(StatusCode::kResourceExhausted, name_,
                         "more than " + std::to_string(kMaxSceneVertices) + " vertices in the scene");
      }
      scene_vertices_ += part.positions.size();
      every_primitive_has_normals = every_primitive_has_normals && !part.normals.empty();
      every_primitive_has_colors = every_primitive_has_colors && !part.colors.empty();
      const uint32_t first_vertex = static_cast<uint32_t>(mesh->positions.size());
      mesh->positions.insert(mesh->positions.end(), part.positions.begin(), part.positions.end());
      mesh->normals.insert(mesh->normals.end(), part.normals.begin(), part.normals.end());
      mesh->colors.insert(mesh->colors.end(), part.colors.begin(), part.colors.end());
      for (const std::array<uint32_t, 3>& triangle : part.triangles) {
        mesh->triangles.push_back({triangle[0] + first_vertex, triangle[1] + first_vertex, triangle[2] + first_vertex});
      }
    }
    if (!every_primitive_has_normals) mesh->normals.clear();
    if (!every_primitive_has_colors) mesh->colors.clear();
    return Status::Ok();
  }

  // Positions by `transform`, normals by its inverse transpose (dropped when it is singular, as a
  // zero scale makes it), the winding reversed when it mirrors.
  Status TransformToScene(const Eigen::Affine3d& transform, const std::string& where, Mesh* mesh) const {
    // Leaves the floats of an untransformed mesh as they are (-0 stays -0).
    const bool identity = transform.matrix() == Eigen::Matrix4d::Identity();
    for (size_t i = 0; i < mesh->positions.size(); ++i) {
      const Eigen::Vector3d position = transform * mesh->positions[i].cast<double>();
      // Also keeps the conversion to float defined.
      if (!(position.array().abs() <= static_cast<double>(std::numeric_limits<float>::max())).all()) {
        return Corrupt(where + ": vertex " + std::to_string(i) + " is not a finite float in the scene's frame");
      }
      if (!identity) mesh->positions[i] = position.cast<float>();
    }
    if (identity) return Status::Ok();
    const Eigen::Matrix3d normal_transform = transform.linear().inverse().transpose();
    if (!normal_transform.allFinite()) mesh->normals.clear();
    for (Eigen::Vector3f& normal : mesh->normals) {
      normal = (normal_transform * normal.cast<double>()).normalized().cast<float>();
    }
    if (transform.linear().determinant() < 0) {
      for (std::array<uint32_t, 3>& triangle : mesh->triangles) std::swap(triangle[1], triangle[2]);
    }
    return Status::Ok();
  }

  std::string_view bytes_;
  const std::string& name_;
  const std::optional<std::string> base_directory_;
  JsonValue json_;
  std::string_view bin_;
  bool has_bin_ = false;
  mutable std::map<size_t, std::string> uri_buffers_;  // the data of buffers with a uri, by buffer index
  std::vector<std::vector<size_t>> node_children_;
  size_t scene_vertices_ = 0;
  bool read_texcoords_ = false;  // TEXCOORD_0 is read (and checked) only for a textured model
};

}  // namespace

Result<Mesh> DecodeGlb(std::string_view bytes, const std::string& name_for_errors) {
  return GlbDecoder(bytes, name_for_errors).Decode();
}

Result<Mesh> ReadGlb(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  return DecodeGlb(bytes, path);
}

Result<TexturedGlb> DecodeTexturedGlb(std::string_view bytes, const std::string& name_for_errors) {
  return GlbDecoder(bytes, name_for_errors, std::nullopt).DecodeTextured(true);
}

Result<TexturedGlb> ReadTexturedGlb(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  return DecodeTexturedGlb(bytes, path);
}

Result<std::vector<NamedMesh>> DecodeGltfScene(std::string_view bytes, const std::string& name_for_errors,
                                               const std::string& base_directory) {
  return GlbDecoder(bytes, name_for_errors, base_directory).DecodeScene();
}

Result<std::vector<NamedMesh>> ReadGltfScene(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  return DecodeGltfScene(bytes, path, std::filesystem::path(path).parent_path().string());
}

}  // namespace reconar
