// EncodeGlb / DecodeGlb: exact round trips, the container layout the glTF 2.0 specification
// requires, hand-made files in the other forms common .glb files use, and damaged or unsupported
// inputs (a Status naming the file, never a crash).
#include "core/mesh/glb_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>

#include "core/base/json_reader.h"
#include "tests/core/mesh/mesh_test_util.h"

namespace reconar {
namespace {

uint32_t Load32(const std::string& bytes, size_t offset) {
  uint32_t value = 0;
  for (int i = 3; i >= 0; --i) value = (value << 8) | static_cast<uint8_t>(bytes[offset + i]);
  return value;
}

void Append32(std::string* out, uint32_t value) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

// A .glb from a JSON text and a BIN payload, padded as the specification requires.
std::string MakeGlb(std::string json, std::string bin, bool with_bin = true) {
  json.resize((json.size() + 3) & ~size_t{3}, ' ');
  bin.resize((bin.size() + 3) & ~size_t{3}, '\0');
  std::string glb;
  Append32(&glb, 0x46546C67);
  Append32(&glb, 2);
  Append32(&glb, static_cast<uint32_t>(12 + 8 + json.size() + (with_bin ? 8 + bin.size() : 0)));
  Append32(&glb, static_cast<uint32_t>(json.size()));
  Append32(&glb, 0x4E4F534A);
  glb += json;
  if (with_bin) {
    Append32(&glb, static_cast<uint32_t>(bin.size()));
    Append32(&glb, 0x004E4942);
    glb += bin;
  }
  return glb;
}

template <typename T>
void AppendValue(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // the tests run on little-endian hosts (x86-64, aarch64)
  out->append(bytes, sizeof(T));
}

struct GlbParts {
  JsonValue json;
  std::string bin;
};

GlbParts Split(const std::string& glb) {
  GlbParts parts;
  const uint32_t json_length = Load32(glb, 12);
  Result<JsonValue> json = ParseJson(std::string_view(glb).substr(20, json_length), "json");
  EXPECT_TRUE(json.ok()) << json.status().ToString();
  if (json.ok()) parts.json = std::move(json).value();
  const size_t bin_header = 20 + json_length;
  if (bin_header + 8 <= glb.size()) parts.bin = glb.substr(bin_header + 8, Load32(glb, bin_header));
  return parts;
}

TEST(GlbTest, RoundTripsAreExact) {
  for (const bool with_normals : {false, true}) {
    for (const bool with_colors : {false, true}) {
      for (const int num_triangles : {0, 1, 700}) {
        const Mesh mesh = testing::RandomMesh(301, num_triangles, with_normals, with_colors, 11);
        const Result<std::string> glb = EncodeGlb(mesh);
        ASSERT_TRUE(glb.ok()) << glb.status().ToString();
        const Result<Mesh> read = DecodeGlb(*glb, "mesh.glb");
        ASSERT_TRUE(read.ok()) << read.status().ToString();
        testing::ExpectMeshesEqual(*read, mesh);
      }
    }
  }
}

TEST(GlbTest, IndexTypeFollowsTheVertexCount) {
  // 65535 vertices: the largest index is 65534, below the reserved 65535, so uint16 suffices.
  for (const int num_vertices : {65535, 65536}) {
    Mesh mesh = testing::RandomMesh(num_vertices, 100, false, false, 5);
    mesh.triangles.push_back({0, static_cast<uint32_t>(num_vertices - 1), 1});
    const Result<std::string> glb = EncodeGlb(mesh);
    ASSERT_TRUE(glb.ok());
    const GlbParts parts = Split(*glb);
    const JsonValue& indices = (*parts.json.Find("accessors"))[1];
    EXPECT_EQ(indices.Find("componentType")->AsInteger(), num_vertices == 65535 ? 5123 : 5125);
    const Result<Mesh> read = DecodeGlb(*glb, "mesh.glb");
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    testing::ExpectMeshesEqual(*read, mesh);
  }
}

TEST(GlbTest, ContainerLayoutFollowsTheSpecification) {
  Mesh mesh = testing::RandomMesh(7, 3, true, true, 2);  // 3 triangles: 18 bytes of uint16, padded
  const Result<std::string> glb = EncodeGlb(mesh);
  ASSERT_TRUE(glb.ok());
  EXPECT_EQ(glb->substr(0, 4), "glTF");
  EXPECT_EQ(Load32(*glb, 4), 2u);
  EXPECT_EQ(Load32(*glb, 8), glb->size());
  EXPECT_EQ(glb->size() % 4, 0u);
  const uint32_t json_length = Load32(*glb, 12);
  EXPECT_EQ(json_length % 4, 0u);
  EXPECT_EQ(glb->substr(16, 4), "JSON");
  EXPECT_EQ(glb->substr(20 + json_length + 4, 4), std::string("BIN\0", 4));
  const GlbParts parts = Split(*glb);
  EXPECT_EQ(parts.bin.size() % 4, 0u);
  const JsonValue& json = parts.json;
  EXPECT_EQ(json.Find("asset")->Find("version")->string(), "2.0");
  EXPECT_EQ(json.Find("asset")->Find("generator")->string(), "reconar");
  EXPECT_EQ(json.Find("buffers")->operator[](0).Find("byteLength")->AsInteger(),
            static_cast<int64_t>(parts.bin.size()));
  const JsonValue& primitive = (*(*json.Find("meshes"))[0].Find("primitives"))[0];
  EXPECT_EQ(primitive.Find("mode")->AsInteger(), 4);
  // POSITION min/max are the exact float extremes.
  const JsonValue& position = (*json.Find("accessors"))[static_cast<size_t>(
      *primitive.Find("attributes")->Find("POSITION")->AsInteger())];
  for (int axis = 0; axis < 3; ++axis) {
    float lo = mesh.positions[0][axis], hi = lo;
    for (const Eigen::Vector3f& p : mesh.positions) {
      lo = std::min(lo, p[axis]);
      hi = std::max(hi, p[axis]);
    }
    EXPECT_EQ((*position.Find("min"))[axis].number(), static_cast<double>(lo));
    EXPECT_EQ((*position.Find("max"))[axis].number(), static_cast<double>(hi));
  }
  const JsonValue& color = (*json.Find("accessors"))[static_cast<size_t>(
      *primitive.Find("attributes")->Find("COLOR_0")->AsInteger())];
  EXPECT_EQ(color.Find("componentType")->AsInteger(), 5121);
  EXPECT_EQ(color.Find("type")->string(), "VEC4");
  EXPECT_TRUE(color.Find("normalized")->bool_value());
  // Every buffer view starts on a 4-byte boundary.
  const JsonValue& views = *json.Find("bufferViews");
  ASSERT_EQ(views.size(), 4u);
  for (size_t i = 0; i < views.size(); ++i) EXPECT_EQ(*views[i].Find("byteOffset")->AsInteger() % 4, 0);
  EXPECT_EQ(views[3].Find("byteLength")->AsInteger(), 18);
}

TEST(GlbTest, PointCloudsUsePointsMode) {
  const Mesh cloud = testing::RandomMesh(50, 0, true, true, 4);
  const Result<std::string> glb = EncodeGlb(cloud);
  ASSERT_TRUE(glb.ok());
  const GlbParts parts = Split(*glb);
  const JsonValue& primitive = (*(*parts.json.Find("meshes"))[0].Find("primitives"))[0];
  EXPECT_EQ(primitive.Find("mode")->AsInteger(), 0);
  EXPECT_EQ(primitive.Find("indices"), nullptr);
  const Result<Mesh> read = DecodeGlb(*glb, "cloud.glb");
  ASSERT_TRUE(read.ok());
  EXPECT_TRUE(read->is_point_cloud());
  testing::ExpectMeshesEqual(*read, cloud);
}

TEST(GlbTest, ReadsInterleavedStridedAndOtherComponentTypes) {
  // One interleaved view: position (3 float) + colour (4 ushort normalized) per vertex, stride 20;
  // float VEC3 normals at a byte offset inside a second view; ubyte indices; no "mode" (TRIANGLES).
  std::string bin;
  const float positions[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.5f}};
  const uint16_t colors[4][4] = {{0, 65535, 32768, 65535}, {65535, 0, 0, 0}, {1, 2, 3, 4}, {257, 514, 771, 1028}};
  for (int i = 0; i < 4; ++i) {
    for (const float v : positions[i]) AppendValue(&bin, v);
    for (const uint16_t v : colors[i]) AppendValue(&bin, v);
  }
  const size_t normals_view = bin.size();  // 80
  AppendValue<float>(&bin, -1.0f);         // 4 bytes skipped by the accessor's byteOffset
  for (int i = 0; i < 4; ++i) {
    AppendValue(&bin, 0.0f);
    AppendValue(&bin, 0.0f);
    AppendValue(&bin, 1.0f);
  }
  const size_t index_view = bin.size();  // 132
  for (const uint8_t index : {0, 1, 2, 2, 1, 3}) bin.push_back(static_cast<char>(index));
  const std::string json = R"({"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":
      {"POSITION":0,"COLOR_0":1,"NORMAL":2,"TEXCOORD_0":0},"indices":3}]}],
    "accessors":[
      {"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},
      {"bufferView":0,"byteOffset":12,"componentType":5123,"normalized":true,"count":4,"type":"VEC4"},
      {"bufferView":1,"byteOffset":4,"componentType":5126,"count":4,"type":"VEC3"},
      {"bufferView":2,"componentType":5121,"count":6,"type":"SCALAR"}],
    "bufferViews":[{"buffer":0,"byteLength":80,"byteStride":20},
                   {"buffer":0,"byteOffset":)" + std::to_string(normals_view) + R"(,"byteLength":52},
                   {"buffer":0,"byteOffset":)" + std::to_string(index_view) + R"(,"byteLength":6}],
    "buffers":[{"byteLength":)" + std::to_string(bin.size()) + "}]}";
  const Result<Mesh> mesh = DecodeGlb(MakeGlb(json, bin), "interleaved.glb");
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  ASSERT_EQ(mesh->positions.size(), 4u);
  EXPECT_EQ(mesh->positions[3], Eigen::Vector3f(1, 1, 0.5f));
  EXPECT_EQ(mesh->normals[2], Eigen::Vector3f(0, 0, 1));
  EXPECT_EQ(mesh->colors[0], (std::array<uint8_t, 4>{0, 255, 128, 255}));
  EXPECT_EQ(mesh->colors[3], (std::array<uint8_t, 4>{1, 2, 3, 4}));  // 257 k / 65535 = k / 255
  const std::vector<std::array<uint32_t, 3>> expected = {{0, 1, 2}, {2, 1, 3}};
  EXPECT_EQ(mesh->triangles, expected);
}

TEST(GlbTest, ReadsNonIndexedTrianglesAndFloatVec3Colours) {
  std::string bin;
  for (int i = 0; i < 6; ++i) {
    AppendValue(&bin, static_cast<float>(i));
    AppendValue(&bin, 0.0f);
    AppendValue(&bin, 0.0f);
  }
  for (int i = 0; i < 6; ++i) {
    AppendValue(&bin, 1.0f);
    AppendValue(&bin, 0.5f);
    AppendValue(&bin, -2.0f);  // clamped
  }
  const std::string json = R"({"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":
      {"POSITION":0,"COLOR_0":1},"mode":4}]}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":6,"type":"VEC3"},
                 {"bufferView":0,"byteOffset":72,"componentType":5126,"count":6,"type":"VEC3"}],
    "bufferViews":[{"buffer":0,"byteLength":144}],"buffers":[{"byteLength":144}]})";
  const Result<Mesh> mesh = DecodeGlb(MakeGlb(json, bin), "flat.glb");
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  const std::vector<std::array<uint32_t, 3>> expected = {{0, 1, 2}, {3, 4, 5}};
  EXPECT_EQ(mesh->triangles, expected);
  EXPECT_EQ(mesh->colors[5], (std::array<uint8_t, 4>{255, 128, 0, 255}));
}

// A valid one-triangle document; the tests below break one thing at a time.
std::string TriangleJson(const std::string& extra_root = "", const std::string& primitive_extra = "",
                         const std::string& accessor0_extra = "", const std::string& buffer_extra = "") {
  return R"({"asset":{"version":"2.0"})" + extra_root +
         R"(,"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1)" + primitive_extra +
         R"(}]}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3")" + accessor0_extra +
         R"(},{"bufferView":1,"componentType":5125,"count":3,"type":"SCALAR"}],
         "bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":12}],
         "buffers":[{"byteLength":48)" + buffer_extra + "}]}";
}

std::string TriangleBin(uint32_t last_index = 2) {
  std::string bin;
  for (int i = 0; i < 9; ++i) AppendValue(&bin, static_cast<float>(i % 4 == 0));
  for (const uint32_t index : {0u, 1u, last_index}) AppendValue(&bin, index);
  return bin;
}

TEST(GlbTest, UnsupportedFeaturesAreNamed) {
  ASSERT_TRUE(DecodeGlb(MakeGlb(TriangleJson(), TriangleBin()), "ok.glb").ok());
  const struct {
    std::string json;
    const char* expected;
  } cases[] = {
      {TriangleJson(R"(,"extensionsRequired":["KHR_draco_mesh_compression"])"), "KHR_draco_mesh_compression"},
      {TriangleJson("", R"(,"extensions":{"KHR_draco_mesh_compression":{"bufferView":0}})"), "draco"},
      {TriangleJson("", "", R"(,"sparse":{"count":1})"), "sparse"},
      {TriangleJson("", "", "", R"(,"uri":"mesh.bin")"), "uri"},
      {TriangleJson("", R"(,"mode":5)"), "mode 5"},
      {std::string(R"({"asset":{"version":"1.0"}})"), "version 1.0"},
  };
  for (const auto& c : cases) {
    const Result<Mesh> mesh = DecodeGlb(MakeGlb(c.json, TriangleBin()), "x.glb");
    ASSERT_FALSE(mesh.ok()) << c.json;
    EXPECT_EQ(mesh.status().code(), StatusCode::kUnsupported) << mesh.status().ToString();
    EXPECT_NE(mesh.status().message().find(c.expected), std::string::npos) << mesh.status().message();
    EXPECT_EQ(mesh.status().message().rfind("x.glb: ", 0), 0u) << mesh.status().message();
  }
}

TEST(GlbTest, CorruptFilesAreNamedNeverCrash) {
  const struct {
    std::string glb;
    const char* expected;
  } cases[] = {
      {MakeGlb(TriangleJson(), TriangleBin(3)), "vertex 3"},
      {MakeGlb(TriangleJson(), TriangleBin(), false), "BIN chunk"},
      {MakeGlb(TriangleJson("", "", R"(,"byteOffset":4)"), TriangleBin()), "accessors[0]"},
      {MakeGlb("{\"asset\":", TriangleBin()), "JSON chunk"},
      {MakeGlb(R"({"asset":{"version":"2.0"}})", ""), "no meshes"},
      {std::string("glTF"), "too short"},
      {std::string("PK\3\4xxxxxxxxxxxxxxxxxxxxxxxxxxx"), "magic"},
  };
  for (const auto& c : cases) {
    const Result<Mesh> mesh = DecodeGlb(c.glb, "bad.glb");
    ASSERT_FALSE(mesh.ok()) << c.expected;
    EXPECT_EQ(mesh.status().code(), StatusCode::kCorruptData) << mesh.status().ToString();
    EXPECT_NE(mesh.status().message().find(c.expected), std::string::npos) << mesh.status().message();
    EXPECT_EQ(mesh.status().message().rfind("bad.glb", 0), 0u) << mesh.status().message();
  }
  // Every truncation and every single-byte change of a real file yields a Status or a mesh.
  const Result<std::string> glb = EncodeGlb(testing::RandomMesh(20, 30, true, true, 9));
  ASSERT_TRUE(glb.ok());
  for (size_t cut = 0; cut < glb->size(); ++cut) {
    EXPECT_FALSE(DecodeGlb(glb->substr(0, cut), "cut.glb").ok()) << cut;
  }
  for (size_t i = 0; i < glb->size(); ++i) {
    std::string damaged = *glb;
    damaged[i] = static_cast<char>(damaged[i] ^ 0x5A);
    const Result<Mesh> mesh = DecodeGlb(damaged, "damaged.glb");
    if (mesh.ok()) {
      EXPECT_TRUE(ValidateMesh(*mesh).ok());
    }
  }
}

TEST(GlbTest, WriterRejectsBadMeshesAndPaths) {
  EXPECT_EQ(EncodeGlb(Mesh()).status().code(), StatusCode::kInvalidArgument);
  Mesh mesh = testing::RandomMesh(5, 2, true, false, 3);
  mesh.positions[2].y() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(EncodeGlb(mesh).status().code(), StatusCode::kInvalidArgument);
  mesh.positions[2].y() = 0;
  mesh.triangles[1][0] = 5;
  EXPECT_EQ(EncodeGlb(mesh).status().code(), StatusCode::kInvalidArgument);
  mesh.triangles[1][0] = 4;
  const std::string path = "/nonexistent_reconar_dir/mesh.glb";
  const Status status = WriteGlb(path, mesh);
  EXPECT_EQ(status.code(), StatusCode::kIoError);
  EXPECT_NE(status.message().find(path), std::string::npos);
  EXPECT_EQ(ReadGlb(path).status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace reconar
