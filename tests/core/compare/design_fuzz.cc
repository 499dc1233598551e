// Mutation fuzzer of the design readers of `reconar compare` (ReadDesign and ParseControl,
// core/compare/design.h).
//
//   design_fuzz [--seconds S] [--seed N] [--format obj|glb|gltf|ply|control|all]
//   (S: CPU seconds of this process; "all": each iteration picks a format)
//
// Starts from valid designs built here (.glb and .gltf scenes with named nodes, a node hierarchy,
// matrix and TRS transforms and data: URI buffers; OBJ files with o/g groups, v/vt/vn, negative
// indices and quads; binary and ascii PLY; a control file with centres, corners, a picked point and
// comments) and applies 1-4 mutations per iteration (tests/support/byte_mutator.h): the byte
// mutations, and for the text formats (and the JSON of glTF) tokens spliced in or put in place of a
// word and lines deleted or duplicated. Most .glb iterations mutate the JSON chunk or the BIN chunk
// alone and frame the file again with the right lengths, so that the damage reaches the glTF
// reader behind the container. Each input is written to /tmp/reconar_design_fuzz_XXXXXX/input.EXT,
// read with ReadDesign (control files: parsed with ParseControl), and the directory is removed at
// the end; a crash leaves it behind with the input that crashed. Every result must be a design or
// a control list whose invariants hold (BrokenInvariant), or a refusal of a legitimate code whose
// message names the input file. A crash or sanitizer report is the failure this harness exists to
// find (run it in an ASan+UBSan build). Exit status 1 when an accepted result breaks an invariant,
// a refusal is not as it should be, or one input takes over 30 s to read (a hang); the input is
// kept.
#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/compare/design.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_io.h"
#include "tests/support/base64.h"
#include "tests/support/byte_mutator.h"
#include "tests/support/design_scene.h"

namespace reconar {
namespace {

using testing::Base64;
using testing::BoxMesh;
using testing::ByteMutator;
using testing::MutationHints;

constexpr unsigned kHangSeconds = 30;
constexpr size_t kMaxRefusalKinds = 20000;  // more distinct messages are counted together
constexpr size_t kRefusalKindsShown = 60;   // the most frequent, in the summary

enum class Format { kObj, kGlb, kGltf, kPly, kControl };
constexpr Format kAllFormats[] = {Format::kObj, Format::kGlb, Format::kGltf, Format::kPly, Format::kControl};

const char* FormatName(Format format) {
  switch (format) {
    case Format::kObj:
      return "obj";
    case Format::kGlb:
      return "glb";
    case Format::kGltf:
      return "gltf";
    case Format::kPly:
      return "ply";
    case Format::kControl:
      return "control";
  }
  return "";
}

const char* Extension(Format format) {
  switch (format) {
    case Format::kObj:
      return ".obj";
    case Format::kGlb:
      return ".glb";
    case Format::kGltf:
      return ".gltf";
    case Format::kPly:
      return ".ply";
    case Format::kControl:
      return ".txt";
  }
  return "";
}

[[noreturn]] void FailSetup(const std::string& message) {
  std::fprintf(stderr, "design_fuzz: %s\n", message.c_str());
  std::exit(2);
}

// ---------------------------------------------------------------------------------------------
// Tokens spliced into the text formats: numbers, white space, the format's words (`words`, separated
// by spaces) and lines (each with its newline).
std::vector<std::string> Tokens(const std::string& words, std::initializer_list<const char*> lines) {
  std::vector<std::string> tokens = {" ", "\t", "\r", "\n"};
  const std::string numbers =
      "0 1 -1 -0 0.5 +1 nan inf -inf 1e309 1e-320 3.5e38 255 256 65535 65536 2147483647 2147483648 4294967295 "
      "4294967296 9223372036854775807 9223372036854775808 18446744073709551616 #";
  for (const std::string& list : {numbers, words}) {
    for (size_t begin = 0; begin < list.size();) {
      const size_t end = std::min(list.find(' ', begin), list.size());
      if (end > begin) tokens.push_back(list.substr(begin, end - begin));
      begin = end + 1;
    }
  }
  for (const char* line : lines) tokens.push_back(std::string(line) + "\n");
  return tokens;
}

std::vector<std::string> ObjTokens() {
  return Tokens("v vn vt f g o / // 0x10",
                {"g", "f 1 2 3", "f -1 -2 -3", "f 1/1/1 2/2/2 3/3/3", "f 1//1 2//2 3//3 4//4", "v 1 2 3",
                 "v 1 2 3 0.5 0.5 0.5", "vn 0 0 1", "usemtl x"});
}

std::vector<std::string> PlyTokens() {
  return Tokens(
      "element property list char uchar short ushort int uint float double vertex face edge x y nx red alpha "
      "vertex_indices vertex_index",
      {"end_header", "format ascii 1.0", "format binary_big_endian 1.0", "format binary_little_endian 1.0", "comment x",
       "element edge 4294967295", "property list uint int vertex_indices", "property float x", "3 0 1 2"});
}

std::vector<std::string> JsonTokens() {
  return Tokens(
      R"({ } [ ] , : " null true false {} [] "" mesh children matrix translation rotation scale nodes scene scenes )"
      R"(name primitives attributes POSITION NORMAL COLOR_0 indices mode accessors bufferView byteOffset byteStride )"
      R"(componentType count normalized type SCALAR VEC2 VEC3 VEC4 buffer byteLength uri sparse extensionsRequired )"
      R"(5120 5121 5122 5123 5125 5126 4 252 1.0e-45 \u0000 \ud800 data:, ,"children":[0] ,"mesh":0 "../x" "x.bin")",
      {});
}

std::vector<std::string> ControlTokens() {
  return Tokens("point 1000000 1000001 0x1f 1e308 -1e309 1,5",
                {"7 0 0 0", "7 0 0 0 1 0 0 1 1 0 0 1 0", "12 1 2 3 # comment"});
}

// ---------------------------------------------------------------------------------------------
// Seeds.

struct Seed {
  Format format;
  std::string bytes;
  size_t num_elements = 0;  // of the design it is (not for control files)
  MutationHints hints;
  // A .glb's chunks apart, for the iterations that mutate one of them and frame the file again.
  std::string json_chunk, bin_chunk;
  MutationHints json_hints, bin_hints;
};

uint32_t LoadUint32(const std::string& bytes, size_t at) {
  uint32_t value = 0;
  for (int i = 3; i >= 0; --i) value = (value << 8) | static_cast<uint8_t>(bytes[at + static_cast<size_t>(i)]);
  return value;
}

void AppendUint32(std::string* bytes, uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes->push_back(static_cast<char>((value >> (8 * i)) & 0xff));
}

// The .glb of a JSON chunk and a BIN chunk, each padded to 4 bytes as the specification asks.
std::string FrameGlb(std::string json, std::string bin) {
  json.resize((json.size() + 3) & ~size_t{3}, ' ');
  bin.resize((bin.size() + 3) & ~size_t{3}, '\0');
  std::string glb = "glTF";
  AppendUint32(&glb, 2);
  AppendUint32(&glb, static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  AppendUint32(&glb, static_cast<uint32_t>(json.size()));
  glb += "JSON";
  glb += json;
  AppendUint32(&glb, static_cast<uint32_t>(bin.size()));
  glb += std::string("BIN\0", 4);
  glb += bin;
  return glb;
}

// The JSON and BIN chunks of a .glb that EncodeGlbScene wrote.
void SplitGlb(const std::string& glb, std::string* json, std::string* bin) {
  const size_t json_length = LoadUint32(glb, 12);
  *json = glb.substr(20, json_length);
  *bin = glb.substr(20 + json_length + 8);
}

void ReplaceOnce(std::string* text, const std::string& from, const std::string& to) {
  const size_t at = text->find(from);
  if (at == std::string::npos) FailSetup("the seed's JSON lacks " + from);
  text->replace(at, from.size(), to);
}

// A slab with normals and colours, a column, a roof with normals and an unnamed beam.
std::vector<NamedMesh> SceneElements() {
  Mesh slab = BoxMesh({-2.0, -2.0, -0.2}, {2.0, 2.0, 0.0});
  ComputeVertexNormals(&slab);
  slab.colors.assign(slab.positions.size(), {200, 190, 180, 255});
  Mesh roof = BoxMesh({-2.1, -2.1, 0.0}, {2.1, 2.1, 0.15});
  ComputeVertexNormals(&roof);
  return {{"slab", slab},
          {"column", BoxMesh({-0.2, -0.2, 0.0}, {0.2, 0.2, 3.0})},
          {"roof", roof},
          {"", BoxMesh({-1.5, -0.1, 2.7}, {1.5, 0.1, 3.0})}};
}

// The scene's nodes as a hierarchy: "frame" (TRS, no mesh) holds "column" (matrix) and an unnamed
// mirrored node that holds "beam" (rotation); "roof" and "slab" are roots beside it, and a node
// outside the scene is left out: 5 elements.
constexpr size_t kHierarchyElements = 5;
const char kHierarchyNodes[] =
    R"("scene":0,"scenes":[{"nodes":[0,3,5]}],"nodes":[)"
    R"({"name":"frame","translation":[1,-2,0.5],"rotation":[0,0,0.3826834323650898,0.9238795325112867],)"
    R"("scale":[2,2,2],"children":[1,2]},)"
    R"({"name":"column","matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0.5,0,0,1],"mesh":1},)"
    R"({"mesh":3,"scale":[-1,1,1],"children":[4]},)"
    R"({"name":"roof","mesh":2,"translation":[0,0,3]},)"
    R"({"name":"beam","mesh":3,"rotation":[0.7071067811865476,0,0,0.7071067811865476]},)"
    R"({"name":"slab","mesh":0},)"
    R"({"name":"outside the scene","mesh":0}])";

Seed GlbSeed(const std::string& json, const std::string& bin, size_t num_elements) {
  Seed seed;
  seed.format = Format::kGlb;
  seed.num_elements = num_elements;
  seed.bytes = FrameGlb(json, bin);
  seed.json_chunk = json;
  seed.bin_chunk = bin;
  const size_t padded_json = LoadUint32(seed.bytes, 12);
  seed.hints.header_bytes = 20;  // the GLB header and the JSON chunk's
  seed.hints.count_offsets = {8, 12, 20 + padded_json};
  seed.json_hints.text_tokens = JsonTokens();
  return seed;
}

// The .gltf text of a .glb's JSON with its BIN chunk as a data: URI, a line per object of an array.
Seed GltfSeed(std::string json, const std::string& bin, size_t num_elements) {
  ReplaceOnce(&json, R"("buffers":[{"byteLength":)" + std::to_string(bin.size()),
              R"("buffers":[{"byteLength":)" + std::to_string(bin.size()) +
                  R"(,"uri":"data:application/octet-stream;base64,)" + Base64(bin) + "\"");
  for (size_t at = 0; (at = json.find("},{", at)) != std::string::npos; at += 4) json.insert(at + 2, "\n");
  Seed seed;
  seed.format = Format::kGltf;
  seed.bytes = json;
  seed.num_elements = num_elements;
  seed.hints.text_tokens = JsonTokens();
  return seed;
}

void AddGlbAndGltfSeeds(std::vector<Seed>* seeds) {
  const std::vector<NamedMesh> elements = SceneElements();
  const Result<std::string> flat = EncodeGlbScene(elements);
  if (!flat.ok()) FailSetup(flat.status().ToString());
  std::string json, bin;
  SplitGlb(*flat, &json, &bin);
  std::string hierarchy_json = json;
  const size_t begin = hierarchy_json.find("\"scene\":");
  const size_t end = hierarchy_json.find(",\"meshes\":");
  if (begin == std::string::npos || end == std::string::npos) FailSetup("unexpected JSON of EncodeGlbScene");
  hierarchy_json.replace(begin, end - begin, kHierarchyNodes);
  seeds->push_back(GlbSeed(json, bin, elements.size()));
  seeds->push_back(GlbSeed(hierarchy_json, bin, kHierarchyElements));
  seeds->push_back(GltfSeed(json, bin, elements.size()));
  seeds->push_back(GltfSeed(hierarchy_json, bin, kHierarchyElements));
}

constexpr int kBoxQuads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
constexpr char kBoxNormals[] = "vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n";

std::string ObjNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.9g", value);
  return text;
}

// The 8 corners of the box [min, max] as "v" lines, in BoxMesh's order.
std::string ObjBoxVertices(const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  std::string text;
  for (int k = 0; k < 8; ++k) {
    text += "v " + ObjNumber(k & 1 ? max.x() : min.x()) + " " + ObjNumber(k & 2 ? max.y() : min.y()) + " " +
            ObjNumber(k & 4 ? max.z() : min.z()) + "\n";
  }
  return text;
}

// The box's 6 faces as quads, counter-clockwise from outside. Vertices are `first_vertex` + 0..7,
// or relative (-8..-1) when `first_vertex` is 0; normals are kBoxNormals' lines, the first numbered
// `first_normal` (relative, -6..-1, when it is negative; none when 0); texture coordinates 1-4
// when `with_texture`.
std::string ObjBoxFaces(int first_vertex, int first_normal, bool with_texture) {
  std::string text;
  for (int face = 0; face < 6; ++face) {
    text += "f";
    for (int corner = 0; corner < 4; ++corner) {
      const int vertex = kBoxQuads[face][corner];
      text += " " + std::to_string(first_vertex > 0 ? first_vertex + vertex : vertex - 8);
      if (with_texture || first_normal != 0) text += "/";
      if (with_texture) text += std::to_string(corner + 1);
      if (first_normal > 0) text += "/" + std::to_string(first_normal + face);
      if (first_normal < 0) text += "/" + std::to_string(face - 6);
    }
    text += "\n";
  }
  return text;
}

void AddObjSeeds(std::vector<Seed>* seeds) {
  std::string groups = "# design_fuzz: a slab, a column and a beam\nmtllib design.mtl\n";
  groups += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  groups += "o slab\n" + ObjBoxVertices({-2, -2, -0.2}, {2, 2, 0}) + kBoxNormals;
  groups += "usemtl concrete\ns off\n" + ObjBoxFaces(1, 1, true);
  groups += "g column\n" + ObjBoxVertices({-0.2, -0.2, 0}, {0.2, 0.2, 3}) + kBoxNormals;
  groups += ObjBoxFaces(0, -1, false);
  groups += "g\nf 1 2 3  # a triangle of the group \"default\"\n";
  groups += "o beam\n" + ObjBoxVertices({-1.5, -0.1, 2.7}, {1.5, 0.1, 3}) + ObjBoxFaces(17, 0, true);
  groups += "l 1 2\np 3\n";

  // Vertex colours, triangles and "v/vt" corners, with CRLF line ends.
  std::string walls = "# design_fuzz: two walls with vertex colours\r\no walls\r\ng wall left\r\n";
  walls += "v 0 0 0 1 0 0\r\nv 0 4 0 1 0 0\r\nv 0 4 2.5 1 0.5 0\r\nv 0 0 2.5 1 0.5 0\r\n";
  walls += "f 1 2 3\r\nf 1 3 4\r\n";
  walls += "g wall right\r\nvt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvt 0 1\r\n";
  walls += "v 3 0 0 0 0 1\r\nv 3 4 0 0 0 1\r\nv 3 4 2.5 0 1 1\r\nv 3 0 2.5 0 1 1\r\n";
  walls += "f 5/1 7/3 6/2\r\nf -4/-4 -1/-1 -2/-2\r\n";

  // The groups: default (its one triangle), slab, column, beam; wall left, wall right.
  for (const auto& [text, num_elements] : {std::make_pair(groups, size_t{4}), std::make_pair(walls, size_t{2})}) {
    Seed seed;
    seed.format = Format::kObj;
    seed.bytes = text;
    seed.num_elements = num_elements;
    seed.hints.text_tokens = ObjTokens();
    seeds->push_back(seed);
  }
}

void AddPlySeeds(const std::string& directory, std::vector<Seed>* seeds) {
  Mesh coloured = BoxMesh({-2.0, -2.0, -0.2}, {2.0, 2.0, 0.0});
  ComputeVertexNormals(&coloured);
  coloured.colors.assign(coloured.positions.size(), {200, 190, 180, 255});
  const Mesh plain = BoxMesh({-0.2, -0.2, 0.0}, {0.2, 0.2, 3.0});
  const std::string path = directory + "/seed.ply";
  struct PlySeedMesh {
    const Mesh* mesh;
    PlyFormat format;
  };
  for (const auto& [mesh, format] :
       {PlySeedMesh{&coloured, PlyFormat::kBinaryLittleEndian}, PlySeedMesh{&plain, PlyFormat::kAscii}}) {
    const Status written = WritePly(path, *mesh, format);
    if (!written.ok()) FailSetup(written.ToString());
    Result<std::string> bytes = ReadFileToString(path);
    if (!bytes.ok()) FailSetup(bytes.status().ToString());
    Seed seed;
    seed.format = Format::kPly;
    seed.bytes = std::move(bytes).value();
    seed.num_elements = 1;
    seed.hints.text_tokens = PlyTokens();
    if (format == PlyFormat::kBinaryLittleEndian) {
      // Each face: its uchar corner count and three int32 vertex indices.
      const size_t faces = seed.bytes.find("end_header\n") + 11 + mesh->positions.size() * (12 + 12 + 4);
      for (size_t face = 0; face < mesh->triangles.size(); ++face) {
        for (size_t offset = 0; offset < 13; offset += (offset == 0 ? 1 : 4)) {
          seed.hints.count_offsets.push_back(faces + 13 * face + offset);
        }
      }
    }
    seeds->push_back(seed);
  }
  std::remove(path.c_str());

  // Quads, properties the reader skips, and an element it does not know.
  std::string scan =
      "ply\nformat ascii 1.0\ncomment design_fuzz: a box as quads\nobj_info scanner\nelement vertex 8\n"
      "property double x\nproperty double y\nproperty double z\nproperty uchar confidence\n"
      "element face 6\nproperty list uchar int vertex_indices\nproperty uchar flags\n"
      "element edge 2\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  for (int k = 0; k < 8; ++k) {
    scan += ObjNumber(k & 1 ? 1.0 : 0.0) + " " + ObjNumber(k & 2 ? 2.0 : 0.0) + " " + ObjNumber(k & 4 ? 0.5 : 0.0) +
            " " + std::to_string(100 + k) + "\n";
  }
  for (const auto& quad : kBoxQuads) {
    scan += "4 " + std::to_string(quad[0]) + " " + std::to_string(quad[1]) + " " + std::to_string(quad[2]) + " " +
            std::to_string(quad[3]) + " 1\n";
  }
  scan += "0 1\n6 7\n";
  Seed seed;
  seed.format = Format::kPly;
  seed.bytes = scan;
  seed.num_elements = 1;
  seed.hints.text_tokens = PlyTokens();
  seeds->push_back(seed);
}

void AddControlSeeds(std::vector<Seed>* seeds) {
  Seed seed;
  seed.format = Format::kControl;
  seed.bytes =
      "# control: the design coordinates of the tags (metres)\n"
      "# ID X Y Z (the centre) or ID and the corners X0 Y0 Z0 .. X3 Y3 Z3\n"
      "0   0.000  0.000 1.200\n"
      "3   1.0 -0.0635 1.0635  1.127 -0.0635 1.0635  1.127 0.0635 1.19  1.0 0.0635 1.19   # tag 3's corners\n"
      "\n"
      "12  2.5 -1 0.75\n"
      "point 0.25 0.5 0  1.31 -0.72 0.004  # a corner of the slab, picked in both\n"
      "\t7 -0.5e1 +2 3e-1\n";
  seed.hints.text_tokens = ControlTokens();
  seeds->push_back(seed);
}

// ---------------------------------------------------------------------------------------------
// Checks.

// The promises of an accepted design (what registration and the deviation rely on).
std::string BrokenInvariant(const Design& design) {
  if (design.elements.empty()) return "no element";
  for (const NamedMesh& element : design.elements) {
    const Mesh& mesh = element.mesh;
    if (element.name.empty()) return "an element without a name";
    if (mesh.triangles.empty()) return "an element without triangles";
    for (const std::array<uint32_t, 3>& triangle : mesh.triangles) {
      for (const uint32_t index : triangle) {
        if (index >= mesh.positions.size()) return "a triangle index beyond the element's vertices";
      }
    }
    for (const Eigen::Vector3f& position : mesh.positions) {
      if (!position.allFinite()) return "a vertex that is not finite";
    }
    const Status valid = ValidateMesh(mesh);
    if (!valid.ok()) return "an inconsistent mesh: " + valid.message();
  }
  return "";
}

std::string BrokenInvariant(const std::vector<ControlTag>& tags) {
  if (tags.empty()) return "no tag and no picked point";
  std::set<int> ids;
  for (const ControlTag& tag : tags) {
    const bool picked = tag.id == -1;
    if (tag.id < -1) return "a negative tag id";
    if (!picked && !ids.insert(tag.id).second) return "a tag id given twice";
    if (picked && tag.design_points.size() != 1) return "a picked point without its one design point";
    if (tag.design_points.size() != 1 && tag.design_points.size() != 4) return "neither 1 nor 4 points";
    for (const Eigen::Vector3d& point : tag.design_points) {
      if (!point.allFinite()) return "a point that is not finite";
    }
    if (!tag.world_point.allFinite()) return "a picked point's world point that is not finite";
  }
  return "";
}

bool LegitimateRefusal(Format format, StatusCode code) {
  switch (code) {
    case StatusCode::kCorruptData:
    case StatusCode::kUnsupported:
    case StatusCode::kResourceExhausted:
    case StatusCode::kInvalidArgument:
      return true;
    case StatusCode::kNotFound:
    case StatusCode::kIoError:
      // A buffer's uri may name a file that is not there, or a directory.
      return format == Format::kGlb || format == Format::kGltf;
    default:
      return false;
  }
}

// The kind of a refusal: its code and message without the file's name, numbers, parenthesised
// details and what is quoted (from the first quote to the last: quoted input may hold quotes).
std::string RefusalKind(const Status& status, const std::string& path) {
  std::string message = status.message();
  for (size_t at = 0; (at = message.find(path, at)) != std::string::npos;) message.erase(at, path.size());
  for (size_t at = 0; (at = message.find("0x", at)) != std::string::npos;) {
    at += 2;
    while (at < message.size() && std::isxdigit(static_cast<unsigned char>(message[at])) != 0) message.erase(at, 1);
  }
  for (const char quote : {'\'', '"'}) {
    const size_t first = message.find(quote);
    const size_t last = message.rfind(quote);
    if (first != last) message.erase(first + 1, last - first - 1);
  }
  std::string kind;
  int depth = 0;
  for (const char c : message) {
    if (c == '(') ++depth;
    const bool kept = depth == 0 && (c < '0' || c > '9') && c >= 0x20 && c < 0x7f;
    if (kept && (!kind.empty() || (c != ' ' && c != ':'))) kind.push_back(c);
    if (c == ')' && depth > 0) --depth;
  }
  return std::string(StatusCodeName(status.code())) + ": " + kind.substr(0, 100);
}

// ---------------------------------------------------------------------------------------------
// The run.

char hang_message[600];
size_t hang_message_length = 0;

void OnHang(int) {
  const ssize_t written = write(STDERR_FILENO, hang_message, hang_message_length);
  (void)written;
  _exit(1);
}

void WriteInput(const std::string& path, const std::string& bytes) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr || std::fwrite(bytes.data(), 1, bytes.size(), file) != bytes.size() || std::fclose(file) != 0) {
    FailSetup("cannot write " + path);
  }
}

// Writes `bytes` to `path` and reads them; "" when the result keeps its promises (*refusal_kind
// set for a refusal, empty for an accepted input), else what is wrong.
std::string CheckInput(Format format, const std::string& bytes, const std::string& path, std::string* refusal_kind) {
  WriteInput(path, bytes);
  hang_message_length = static_cast<size_t>(std::snprintf(hang_message, sizeof(hang_message),
                                                          "design_fuzz: %s took over %u s to read (a hang?)\n",
                                                          path.c_str(), kHangSeconds));
  hang_message_length = std::min(hang_message_length, sizeof(hang_message) - 1);
  alarm(kHangSeconds);
  Status refusal;
  std::string broken;
  if (format == Format::kControl) {
    const Result<std::vector<ControlTag>> tags = ParseControl(bytes, path);
    if (tags.ok()) broken = BrokenInvariant(*tags);
    refusal = tags.status();
  } else {
    const Result<Design> design = ReadDesign(path);
    if (design.ok()) broken = BrokenInvariant(*design);
    refusal = design.status();
    if (format == Format::kGlb && broken.empty()) {
      // The textured model's reader (`reconar view`, `render`) on the same bytes.
      const Result<TexturedGlb> textured = DecodeTexturedGlb(bytes, path);
      if (textured.ok() && !ValidateMesh(textured->mesh).ok()) {
        broken = "DecodeTexturedGlb: " + ValidateMesh(textured->mesh).ToString();
      } else if (!textured.ok() && (!LegitimateRefusal(format, textured.status().code()) ||
                                    textured.status().message().find(path) == std::string::npos)) {
        broken = "DecodeTexturedGlb refused badly: " + textured.status().ToString();
      }
    }
  }
  alarm(0);
  refusal_kind->clear();
  if (!broken.empty()) return "an accepted result breaks an invariant: " + broken;
  if (refusal.ok()) return "";
  if (!LegitimateRefusal(format, refusal.code())) return "unexpected status " + refusal.ToString();
  if (refusal.message().find(path) == std::string::npos)
    return "the refusal does not name the file: " + refusal.ToString();
  *refusal_kind = RefusalKind(refusal, path);
  return "";
}

struct FormatCounts {
  long iterations = 0;
  long accepted = 0;
  long refused = 0;
};

int Run(double seconds, uint64_t seed_value, const std::vector<Format>& formats) {
  char directory_template[] = "/tmp/reconar_design_fuzz_XXXXXX";
  if (mkdtemp(directory_template) == nullptr) FailSetup("cannot create a directory under /tmp");
  const std::string directory = directory_template;
  std::vector<Seed> seeds;
  AddObjSeeds(&seeds);
  AddGlbAndGltfSeeds(&seeds);
  AddPlySeeds(directory, &seeds);
  AddControlSeeds(&seeds);

  std::map<Format, std::vector<const Seed*>> seeds_of;
  for (const Seed& seed : seeds) seeds_of[seed.format].push_back(&seed);
  std::map<Format, std::string> input_path;
  for (const Format format : kAllFormats) input_path[format] = directory + "/input" + Extension(format);

  std::string refusal_kind;
  for (const Seed& seed : seeds) {
    const std::string& path = input_path[seed.format];
    const std::string failure = CheckInput(seed.format, seed.bytes, path, &refusal_kind);
    if (!failure.empty() || !refusal_kind.empty()) {
      FailSetup(std::string("a valid ") + FormatName(seed.format) + " seed: " + failure + refusal_kind);
    }
    if (seed.format == Format::kControl) continue;
    const Result<Design> design = ReadDesign(path);
    if (design->elements.size() != seed.num_elements) {
      FailSetup(std::string("a valid ") + FormatName(seed.format) + " seed gives " +
                std::to_string(design->elements.size()) + " elements, not " + std::to_string(seed.num_elements));
    }
  }
  signal(SIGALRM, OnHang);

  ByteMutator mutator(seed_value);
  std::map<Format, FormatCounts> counts;
  std::map<std::string, long> refusals;
  long iterations = 0;
  long reframed = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  const auto cpu_seconds = [&] { return static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC; };
  std::string bytes;
  while (cpu_seconds() < seconds) {
    const Format format = formats[static_cast<size_t>(mutator.Uniform(0, static_cast<int>(formats.size()) - 1))];
    const std::vector<const Seed*>& candidates = seeds_of[format];
    const Seed& seed = *candidates[static_cast<size_t>(mutator.Uniform(0, static_cast<int>(candidates.size()) - 1))];
    const int num_mutations = mutator.Chance(0.6) ? 1 : mutator.Uniform(2, 4);
    if (format == Format::kGlb && mutator.Chance(0.85)) {
      std::string json = seed.json_chunk, bin = seed.bin_chunk;
      for (int i = 0; i < num_mutations; ++i) {
        if (mutator.Chance(0.75)) {
          mutator.Mutate(seed.json_hints, &json);
        } else {
          mutator.Mutate(seed.bin_hints, &bin);
        }
      }
      bytes = FrameGlb(json, bin);
      ++reframed;
    } else {
      bytes = seed.bytes;
      for (int i = 0; i < num_mutations; ++i) mutator.Mutate(seed.hints, &bytes);
    }
    ++iterations;
    FormatCounts& count = counts[format];
    ++count.iterations;
    const std::string failure = CheckInput(format, bytes, input_path[format], &refusal_kind);
    if (!failure.empty()) {
      const std::string kept = directory + "/failure" + Extension(format);
      std::rename(input_path[format].c_str(), kept.c_str());
      std::fprintf(stderr, "design_fuzz: iteration %ld (%s): %s\n  input kept at %s\n", iterations, FormatName(format),
                   failure.c_str(), kept.c_str());
      return 1;
    }
    if (refusal_kind.empty()) {
      ++count.accepted;
      continue;
    }
    ++count.refused;
    const std::string key = std::string(FormatName(format)) + "  " + refusal_kind;
    if (refusals.size() < kMaxRefusalKinds || refusals.count(key) > 0) {
      ++refusals[key];
    } else {
      ++refusals[std::string(FormatName(format)) + "  (other kinds)"];
    }
  }
  const double wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::filesystem::remove_all(directory);

  long accepted = 0, refused = 0;
  for (const auto& [format, count] : counts) {
    accepted += count.accepted;
    refused += count.refused;
  }
  std::printf(
      "design_fuzz: seed %llu, %.1f CPU s (%.1f s wall), %ld iterations (%ld .glb with the chunks framed again): "
      "%ld accepted, %ld refused\n",
      static_cast<unsigned long long>(seed_value), cpu_seconds(), wall_seconds, iterations, reframed, accepted,
      refused);
  for (const auto& [format, count] : counts) {
    std::printf("  %-8s %8ld iterations, %8ld accepted, %8ld refused\n", FormatName(format), count.iterations,
                count.accepted, count.refused);
  }
  std::vector<std::pair<std::string, long>> by_count(refusals.begin(), refusals.end());
  std::stable_sort(by_count.begin(), by_count.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  const size_t shown = std::min(by_count.size(), kRefusalKindsShown);
  for (size_t k = 0; k < shown; ++k) std::printf("  %8ld  %s\n", by_count[k].second, by_count[k].first.c_str());
  if (by_count.size() > shown) {
    long left_out = 0;
    for (size_t k = shown; k < by_count.size(); ++k) left_out += by_count[k].second;
    std::printf("  %zu other kinds of refusal left out (%ld refusals)\n", by_count.size() - shown, left_out);
  }
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) {
  double seconds = 10.0;
  uint64_t seed = 1;
  std::vector<reconar::Format> formats(std::begin(reconar::kAllFormats), std::end(reconar::kAllFormats));
  bool usage_error = false;
  for (int i = 1; i < argc && !usage_error; ++i) {
    const std::string arg = argv[i];
    if (arg == "--seconds" && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
    } else if (arg == "--seed" && i + 1 < argc) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (arg == "--format" && i + 1 < argc) {
      const std::string name = argv[++i];
      if (name != "all") {
        formats.clear();
        for (const reconar::Format format : reconar::kAllFormats) {
          if (name == reconar::FormatName(format)) formats.push_back(format);
        }
        usage_error = formats.empty();
      }
    } else {
      usage_error = true;
    }
  }
  if (usage_error) {
    std::fprintf(stderr, "usage: %s [--seconds S] [--seed N] [--format obj|glb|gltf|ply|control|all]\n", argv[0]);
    return 2;
  }
  return reconar::Run(seconds, seed, formats);
}
