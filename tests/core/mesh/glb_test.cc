// EncodeGlb / DecodeGlb: exact round trips, the container layout the glTF 2.0 specification
// requires, hand-made files in the other forms common .glb files use, and damaged or unsupported
// inputs (a Status naming the file, never a crash).
#include "core/mesh/glb_io.h"
#include "tests/support/base64.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "tests/core/mesh/mesh_test_util.h"

namespace reconar {
namespace {

using testing::DataUri;

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

TEST(GlbTest, TexturedRoundTripKeepsTexcoordsAndTheImage) {
  Mesh mesh = testing::RandomMesh(301, 700, true, true, 5);
  for (size_t i = 0; i < mesh.positions.size(); ++i) mesh.texcoords.emplace_back(i / 301.0f, 1.0f - i / 602.0f);
  const std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + "image bytes";
  const Result<std::string> glb = EncodeTexturedGlb(mesh, {{0, png}});
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  const GlbParts parts = Split(*glb);
  const JsonValue* material = parts.json.Find("materials");
  ASSERT_NE(material, nullptr);
  EXPECT_EQ((*parts.json.Find("images"))[0].Find("mimeType")->string(), "image/png");
  EXPECT_EQ((*parts.json.Find("meshes"))[0].Find("primitives")->operator[](0).Find("material")->AsInteger(), 0);

  const Result<TexturedGlb> read = DecodeTexturedGlb(*glb, "textured.glb");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->pages.size(), 1u);
  EXPECT_EQ(read->pages[0].first_triangle, 0u);
  EXPECT_EQ(read->pages[0].image, png);
  ASSERT_EQ(read->mesh.texcoords.size(), mesh.texcoords.size());
  for (size_t i = 0; i < mesh.texcoords.size(); ++i) EXPECT_EQ(read->mesh.texcoords[i], mesh.texcoords[i]);
  Mesh without_texcoords = read->mesh;
  without_texcoords.texcoords.clear();
  Mesh expected = mesh;
  expected.texcoords.clear();
  testing::ExpectMeshesEqual(without_texcoords, expected);
  // The plain reader leaves the texture out, so that code unaware of texcoords never meets them.
  const Result<Mesh> plain = DecodeGlb(*glb, "textured.glb");
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->texcoords.empty());
  // An untextured file reads as a TexturedGlb without image or texcoords.
  const Result<TexturedGlb> untextured = DecodeTexturedGlb(*EncodeGlb(expected), "plain.glb");
  ASSERT_TRUE(untextured.ok());
  EXPECT_TRUE(untextured->pages.empty());
  EXPECT_TRUE(untextured->mesh.texcoords.empty());
}

TEST(GlbTest, TexturedWritingRefusesWhatCannotBeATexturedModel) {
  Mesh mesh = testing::RandomMesh(10, 5, false, false, 5);
  const std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + "x";
  EXPECT_EQ(EncodeTexturedGlb(mesh, {{0, png}}).status().code(), StatusCode::kInvalidArgument);  // no texcoords
  mesh.texcoords.assign(10, Eigen::Vector2f(0.5f, 0.5f));
  EXPECT_EQ(EncodeTexturedGlb(mesh, {{0, "GIF89a"}}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(EncodeTexturedGlb(mesh, {}).status().code(), StatusCode::kInvalidArgument);             // no page
  EXPECT_EQ(EncodeTexturedGlb(mesh, {{1, png}}).status().code(), StatusCode::kInvalidArgument);     // not at 0
  EXPECT_EQ(EncodeTexturedGlb(mesh, {{0, png}, {9, png}}).status().code(), StatusCode::kInvalidArgument);  // past
  mesh.texcoords[3].x() = NAN;
  EXPECT_EQ(EncodeTexturedGlb(mesh, {{0, png}}).status().code(), StatusCode::kInvalidArgument);
  mesh.texcoords.resize(4);
  EXPECT_EQ(EncodeTexturedGlb(mesh, {{0, png}}).status().code(), StatusCode::kInvalidArgument);
}

// Pages as texturing writes them, each page's vertices its own, with a fake PNG each.
struct PagedMesh {
  std::vector<NamedMesh> parts;
  std::vector<EncodedTexturePage> pages;
};

PagedMesh MakePagedMesh(int num_pages) {
  PagedMesh paged;
  size_t first = 0;
  for (int k = 0; k < num_pages; ++k) {
    Mesh part = testing::RandomMesh(50 + 10 * k, 80 + k, true, false, 7 + static_cast<unsigned>(k));
    for (size_t i = 0; i < part.positions.size(); ++i) part.texcoords.emplace_back(i / 100.0f, 0.25f * k);
    paged.pages.push_back({first, std::string("\x89PNG\r\n\x1a\n", 8) + "page " + std::to_string(k)});
    first += part.triangles.size();
    paged.parts.push_back({"", std::move(part)});
  }
  return paged;
}

TEST(GlbTest, TexturePagesAreOnePrimitiveAndMaterialEach) {
  const PagedMesh paged = MakePagedMesh(3);
  const Mesh mesh = JoinMeshes(paged.parts);
  const std::vector<EncodedTexturePage>& pages = paged.pages;
  const Result<std::string> glb = EncodeTexturedGlb(mesh, pages);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  const GlbParts split = Split(*glb);
  const JsonValue& primitives = *(*split.json.Find("meshes"))[0].Find("primitives");
  ASSERT_EQ(primitives.size(), 3u);
  for (size_t k = 0; k < 3; ++k) EXPECT_EQ(primitives[k].Find("material")->AsInteger(), static_cast<int64_t>(k));
  EXPECT_EQ(split.json.Find("materials")->size(), 3u);
  EXPECT_EQ(split.json.Find("images")->size(), 3u);
  EXPECT_EQ(split.json.Find("nodes")->size(), 1u);

  const Result<TexturedGlb> read = DecodeTexturedGlb(*glb, "pages.glb");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->pages.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(read->pages[k].first_triangle, pages[k].first_triangle);
    EXPECT_EQ(read->pages[k].image, pages[k].image);
  }
  // Every corner of every triangle where it was, with its normal and texcoord (a page's vertices
  // may come back in another order).
  ASSERT_EQ(read->mesh.triangles.size(), mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (size_t c = 0; c < 3; ++c) {
      const uint32_t a = read->mesh.triangles[t][c], b = mesh.triangles[t][c];
      EXPECT_EQ(read->mesh.positions[a], mesh.positions[b]);
      EXPECT_EQ(read->mesh.normals[a], mesh.normals[b]);
      EXPECT_EQ(read->mesh.texcoords[a], mesh.texcoords[b]);
    }
  }
}

TEST(GlbTest, APageWithoutAnImageLeavesTheFirstPrimitiveAlone) {
  // Two textured pages, then the second's material taken away: not a paged texture any more, so
  // the first primitive is read alone, as a file that only it textures.
  const PagedMesh paged = MakePagedMesh(2);
  const Result<std::string> glb = EncodeTexturedGlb(JoinMeshes(paged.parts), paged.pages);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  std::string json = glb->substr(20, Load32(*glb, 12));
  const std::string member = ",\"material\":1";
  const size_t material = json.find(member);
  ASSERT_NE(material, std::string::npos) << json;
  json.erase(material, member.size());
  const Result<TexturedGlb> read = DecodeTexturedGlb(MakeGlb(json, Split(*glb).bin), "one_page.glb");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->pages.size(), 1u);
  EXPECT_EQ(read->pages[0].image, paged.pages[0].image);
  const Mesh& first = paged.parts[0].mesh;
  ASSERT_EQ(read->mesh.triangles.size(), first.triangles.size());
  ASSERT_EQ(read->mesh.positions.size(), first.positions.size());
  EXPECT_EQ(read->mesh.normals.size(), first.positions.size());
  EXPECT_EQ(read->mesh.texcoords.size(), first.positions.size());
  for (size_t t = 0; t < first.triangles.size(); ++t) {
    for (size_t c = 0; c < 3; ++c) {
      EXPECT_EQ(read->mesh.positions[read->mesh.triangles[t][c]], first.positions[first.triangles[t][c]]);
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

// FNV-1a, 64 bits: a fingerprint of the bytes EncodeGlb wrote before it became EncodeGlbScene's
// one-element case.
uint64_t Fingerprint(const std::string& bytes) {
  uint64_t hash = 14695981039346656037ull;
  for (const char c : bytes) hash = (hash ^ static_cast<uint8_t>(c)) * 1099511628211ull;
  return hash;
}

TEST(GlbTest, EncodeGlbWritesTheSameBytesAsBefore) {
  // Meshes with exactly representable coordinates, so that no platform writes other digits.
  Mesh plain = testing::GridMesh(2, 1.0f, 0.5f);
  Mesh shaded = testing::GridMesh(4, 2.0f, 0.0f);
  for (size_t i = 0; i < shaded.positions.size(); ++i) {
    shaded.normals.emplace_back(0.0f, 0.0f, 1.0f);
    shaded.colors.push_back({static_cast<uint8_t>(i), static_cast<uint8_t>(2 * i), static_cast<uint8_t>(3 * i), 255});
  }
  Mesh cloud = testing::GridMesh(3, 1.0f, -1.0f);
  cloud.triangles.clear();
  const Mesh uint32_indices = testing::GridMesh(256, 1.0f, 0.25f);
  const struct {
    const Mesh* mesh;
    size_t size;
    uint64_t fingerprint;
  } cases[] = {
      {&plain, 712, 0xee0815575b3785fdull},
      {&shaded, 1736, 0x4a6934d6acc20315ull},
      {&cloud, 608, 0x77b93e49f1726365ull},
      {&uint32_indices, 2366032, 0xb610a1088b66a2abull},
  };
  for (const auto& c : cases) {
    const Result<std::string> glb = EncodeGlb(*c.mesh);
    ASSERT_TRUE(glb.ok()) << glb.status().ToString();
    EXPECT_EQ(glb->size(), c.size);
    EXPECT_EQ(Fingerprint(*glb), c.fingerprint) << c.size;
    const Result<std::string> scene = EncodeGlbScene({{"", *c.mesh}});
    ASSERT_TRUE(scene.ok()) << scene.status().ToString();
    EXPECT_EQ(*scene, *glb);
  }
}

// ---------------------------------------------------------------------------------------------
// Scenes: EncodeGlbScene / DecodeGltfScene.

namespace fs = std::filesystem;

class GlbSceneTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("reconar_glb_scene_" + std::to_string(::getpid())) / info->name();
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }

  fs::path dir_;
};

// An axis-aligned box from `low` to `high`: 8 vertices, 12 triangles counter-clockwise from outside.
Mesh Box(const Eigen::Vector3f& low, const Eigen::Vector3f& high) {
  Mesh box;
  for (int corner = 0; corner < 8; ++corner) {
    box.positions.emplace_back(corner & 1 ? high.x() : low.x(), corner & 2 ? high.y() : low.y(),
                               corner & 4 ? high.z() : low.z());
  }
  box.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return box;
}

TEST_F(GlbSceneTest, NamedBoxesRoundTrip) {
  std::vector<NamedMesh> boxes = {{"wall", Box({0, 0, 0}, {4, 0.2f, 2.5f})},
                                  {"column \"C3\"", Box({1, 1, 0}, {1.3f, 1.3f, 2.5f})},
                                  {"slab", Box({-0.5f, -0.5f, -0.25f}, {4.5f, 3.5f, 0})}};
  ComputeVertexNormals(&boxes[1].mesh);
  for (size_t i = 0; i < boxes[1].mesh.positions.size(); ++i) {
    boxes[1].mesh.colors.push_back({static_cast<uint8_t>(30 * i), 200, 7, 255});
  }
  const Result<std::string> glb = EncodeGlbScene(boxes);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  const GlbParts parts = Split(*glb);
  const JsonValue& nodes = *parts.json.Find("nodes");
  ASSERT_EQ(nodes.size(), 3u);
  EXPECT_EQ(nodes[1].Find("name")->string(), "column \"C3\"");
  EXPECT_EQ(nodes[2].Find("mesh")->AsInteger(), 2);
  EXPECT_EQ(parts.json.Find("meshes")->size(), 3u);
  EXPECT_EQ((*(*parts.json.Find("scenes"))[0].Find("nodes")).size(), 3u);

  const Result<std::vector<NamedMesh>> read = DecodeGltfScene(*glb, "boxes.glb", "");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->size(), boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) {
    EXPECT_EQ((*read)[i].name, boxes[i].name);
    EXPECT_EQ((*read)[i].mesh.positions.size(), boxes[i].mesh.positions.size());
    testing::ExpectMeshesEqual((*read)[i].mesh, boxes[i].mesh);
  }

  // Through files; an element without a name is read back under its node's number.
  boxes.push_back({"", Box({0, 0, 3}, {1, 1, 4})});
  const std::string path = (dir_ / "design.glb").string();
  ASSERT_TRUE(WriteGlbScene(path, boxes).ok());
  const Result<std::vector<NamedMesh>> from_file = ReadGltfScene(path);
  ASSERT_TRUE(from_file.ok()) << from_file.status().ToString();
  ASSERT_EQ(from_file->size(), 4u);
  EXPECT_EQ((*from_file)[3].name, "node 3");
  testing::ExpectMeshesEqual((*from_file)[3].mesh, boxes[3].mesh);
  // ReadGlb still reads the first mesh alone.
  const Result<Mesh> first = ReadGlb(path);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  testing::ExpectMeshesEqual(*first, boxes[0].mesh);
}

TEST(GlbTest, SceneWriterRejectsBadElements) {
  EXPECT_EQ(EncodeGlbScene({}).status().code(), StatusCode::kInvalidArgument);
  std::vector<NamedMesh> meshes = {{"a", Box({0, 0, 0}, {1, 1, 1})}, {"b", Box({0, 0, 0}, {1, 1, 1})}};
  meshes[1].mesh.positions[3].x() = std::numeric_limits<float>::infinity();
  Result<std::string> glb = EncodeGlbScene(meshes);
  EXPECT_EQ(glb.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(glb.status().message().find("element 1 'b'"), std::string::npos) << glb.status().message();
  meshes[1].mesh.positions[3].x() = 1;
  meshes[0].name = "caf\xC3";  // a truncated UTF-8 sequence
  glb = EncodeGlbScene(meshes);
  EXPECT_EQ(glb.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(glb.status().message().find("UTF-8"), std::string::npos) << glb.status().message();
  const Status status = WriteGlbScene("/nonexistent_reconar_dir/design.glb", {{"a", Box({0, 0, 0}, {1, 1, 1})}});
  EXPECT_EQ(status.code(), StatusCode::kIoError);
}


std::string JsonNumbers(const double* values, int count) {
  std::string text;
  for (int i = 0; i < count; ++i) {
    char number[32];
    std::snprintf(number, sizeof(number), "%.17g", values[i]);
    text += (i == 0 ? "" : ",") + std::string(number);
  }
  return text;
}

// The transforms of HierarchyGltf's parent node (translation, rotation, scale) and child node (matrix).
struct HierarchyTransforms {
  Eigen::Vector3d translation{1, -2, 3};
  Eigen::Quaterniond rotation{Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 2).normalized())};  // coeffs(): x y z w
  Eigen::Vector3d scale{2, 0.5, 1.5};
  Eigen::Matrix4d child;
};

HierarchyTransforms MakeHierarchyTransforms() {
  HierarchyTransforms transforms;
  transforms.child << 0.8, -0.6, 0.2, 4,  //
      0.6, 0.8, 0.0, 5,                  //
      0.1, 0.0, 1.2, -6,                 //
      0, 0, 0, 1;
  return transforms;
}

// BIN: positions of primitive A (36 bytes), of B (36), normals (36), A's colours (12), B's ubyte
// indices (3 + 1).
std::string HierarchyBin() {
  std::string bin;
  const float positions[6][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 1}, {0, 3, 1}};
  for (const auto& p : positions) {
    for (const float v : p) AppendValue(&bin, v);
  }
  for (int i = 0; i < 3; ++i) {
    AppendValue(&bin, 0.0f);
    AppendValue(&bin, 0.0f);
    AppendValue(&bin, 1.0f);
  }
  for (const uint8_t c : {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255}) bin.push_back(static_cast<char>(c));
  for (const uint8_t index : {0, 2, 1, 0}) bin.push_back(static_cast<char>(index));
  return bin;
}

// Node 0 "parent" (TRS) holds node 1 "child" (matrix, mesh 0: TRIANGLES A with colours, TRIANGLES
// B without, POINTS skipped); node 2 (no name, mesh 1 "fallback") holds node 4 (no name, mesh 2
// unnamed, mirrored by scale -1 in x); node 3 "hidden" is a root outside the scene.
std::string HierarchyGltf(const std::string& uri) {
  const HierarchyTransforms transforms = MakeHierarchyTransforms();
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,2]}],
    "nodes":[
      {"name":"parent","translation":[)" + JsonNumbers(transforms.translation.data(), 3) + R"(],
       "rotation":[)" + JsonNumbers(transforms.rotation.coeffs().data(), 4) + R"(],
       "scale":[)" + JsonNumbers(transforms.scale.data(), 3) + R"(],"children":[1]},
      {"name":"child","matrix":[)" + JsonNumbers(transforms.child.data(), 16) + R"(],"mesh":0},
      {"mesh":1,"children":[4]},
      {"name":"hidden","mesh":0},
      {"mesh":2,"scale":[-1,1,1]}],
    "meshes":[
      {"name":"from the mesh","primitives":[{"attributes":{"POSITION":0,"NORMAL":2,"COLOR_0":3}},
                                           {"attributes":{"POSITION":1,"NORMAL":2},"indices":4,"mode":4},
                                           {"attributes":{"POSITION":1},"mode":0}]},
      {"name":"fallback","primitives":[{"attributes":{"POSITION":1},"indices":4}]},
      {"primitives":[{"attributes":{"POSITION":0,"NORMAL":2,"COLOR_0":3}}]}],
    "accessors":[
      {"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},
      {"bufferView":0,"byteOffset":36,"componentType":5126,"count":3,"type":"VEC3"},
      {"bufferView":0,"byteOffset":72,"componentType":5126,"count":3,"type":"VEC3"},
      {"bufferView":1,"componentType":5121,"normalized":true,"count":3,"type":"VEC4"},
      {"bufferView":2,"componentType":5121,"count":3,"type":"SCALAR"}],
    "bufferViews":[{"buffer":0,"byteLength":108},{"buffer":0,"byteOffset":108,"byteLength":12},
                   {"buffer":0,"byteOffset":120,"byteLength":3}],
    "buffers":[{"byteLength":124,"uri":")" + uri + R"("}]})";
}

void ExpectHierarchyScene(const Result<std::vector<NamedMesh>>& scene) {
  ASSERT_TRUE(scene.ok()) << scene.status().ToString();
  ASSERT_EQ(scene->size(), 3u);
  EXPECT_EQ((*scene)[0].name, "child");
  EXPECT_EQ((*scene)[1].name, "fallback");
  EXPECT_EQ((*scene)[2].name, "node 4");

  // The child: both TRIANGLES primitives, in the parent's frame composed with its own.
  const HierarchyTransforms transforms = MakeHierarchyTransforms();
  const Eigen::Affine3d parent_to_scene =
      Eigen::Translation3d(transforms.translation) * transforms.rotation * Eigen::Scaling(transforms.scale);
  const Eigen::Affine3d child_to_scene = parent_to_scene * Eigen::Affine3d(transforms.child);
  const Eigen::Vector3d local[6] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 1}, {0, 3, 1}};
  const Mesh& child = (*scene)[0].mesh;
  ASSERT_EQ(child.positions.size(), 6u);
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d expected = child_to_scene * local[i];
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_NEAR(child.positions[i][axis], expected[axis], 1e-5 * (1 + std::abs(expected[axis]))) << i;
    }
  }
  const Eigen::Vector3d expected_normal =
      (child_to_scene.linear().inverse().transpose() * Eigen::Vector3d::UnitZ()).normalized();
  ASSERT_EQ(child.normals.size(), 6u);
  for (const Eigen::Vector3f& normal : child.normals) {
    EXPECT_LT((normal.cast<double>() - expected_normal).norm(), 1e-6) << normal.transpose();
  }
  EXPECT_TRUE(child.colors.empty());  // primitive B has none
  const std::vector<std::array<uint32_t, 3>> child_triangles = {{0, 1, 2}, {3, 5, 4}};
  EXPECT_EQ(child.triangles, child_triangles);

  // Node 2 has no transform: its floats as they are in the buffer.
  const Mesh& fallback = (*scene)[1].mesh;
  ASSERT_EQ(fallback.positions.size(), 3u);
  EXPECT_EQ(fallback.positions[2], Eigen::Vector3f(0, 3, 1));
  EXPECT_TRUE(fallback.normals.empty());

  // Node 4 mirrors: x negated, the winding reversed so that the triangle still faces its normal.
  const Mesh& mirrored = (*scene)[2].mesh;
  ASSERT_EQ(mirrored.positions.size(), 3u);
  EXPECT_EQ(mirrored.positions[1], Eigen::Vector3f(-1, 0, 0));
  EXPECT_EQ(mirrored.normals[0], Eigen::Vector3f(0, 0, 1));
  const std::vector<std::array<uint32_t, 3>> mirrored_triangles = {{0, 2, 1}};
  EXPECT_EQ(mirrored.triangles, mirrored_triangles);
  EXPECT_EQ(mirrored.colors[1], (std::array<uint8_t, 4>{0, 255, 0, 255}));
}

TEST_F(GlbSceneTest, HierarchyWithDataUri) {
  ExpectHierarchyScene(DecodeGltfScene(HierarchyGltf(DataUri(HierarchyBin())), "design.gltf", ""));
}

TEST_F(GlbSceneTest, HierarchyWithExternalBufferFile) {
  fs::create_directories(dir_ / "parts");
  ASSERT_TRUE(WriteFileAtomically((dir_ / "parts" / "design data.bin").string(), HierarchyBin()).ok());
  const std::string path = (dir_ / "design.gltf").string();
  ASSERT_TRUE(WriteFileAtomically(path, HierarchyGltf("parts/design%20data.bin")).ok());
  ExpectHierarchyScene(ReadGltfScene(path));
  // The same JSON in a .glb without a BIN chunk.
  std::string glb_json = HierarchyGltf("parts/design%20data.bin");
  ASSERT_TRUE(WriteFileAtomically((dir_ / "design.glb").string(), MakeGlb(glb_json, "", false)).ok());
  ExpectHierarchyScene(ReadGltfScene((dir_ / "design.glb").string()));
}

// TriangleJson's document as a .gltf: its buffer is `uri`, `nodes` its root members after "asset".
std::string TriangleGltf(const std::string& nodes, const std::string& uri = DataUri(TriangleBin()),
                         const std::string& primitive_extra = "") {
  return TriangleJson(nodes, primitive_extra, "", R"(,"uri":")" + uri + "\"");
}

TEST(GlbTest, SceneRootsAreTheDefaultScenesOrEveryRoot) {
  const std::string nodes = R"(,"nodes":[{"name":"a","mesh":0},{"name":"b","mesh":0,"children":[2]},
                                         {"name":"c","mesh":0,"translation":[0,0,1]}])";
  const struct {
    std::string scenes;
    std::vector<std::string> names;
  } cases[] = {
      {"", {"a", "b", "c"}},
      {R"(,"scenes":[{"nodes":[1]}])", {"b", "c"}},
      {R"(,"scene":1,"scenes":[{"nodes":[1]},{"nodes":[0]}])", {"a"}},
  };
  for (const auto& c : cases) {
    const Result<std::vector<NamedMesh>> scene = DecodeGltfScene(TriangleGltf(nodes + c.scenes), "roots.gltf", "");
    ASSERT_TRUE(scene.ok()) << scene.status().ToString();
    std::vector<std::string> names;
    for (const NamedMesh& element : *scene) names.push_back(element.name);
    EXPECT_EQ(names, c.names) << c.scenes;
  }
  const Result<std::vector<NamedMesh>> scene = DecodeGltfScene(TriangleGltf(nodes), "roots.gltf", "");
  ASSERT_TRUE(scene.ok());
  EXPECT_EQ((*scene)[2].mesh.positions[0], Eigen::Vector3f(1, 0, 1));  // c's translation
}

TEST_F(GlbSceneTest, ErrorsNameTheFile) {
  const std::string one_node = R"(,"nodes":[{"mesh":0}])";
  ASSERT_TRUE(DecodeGltfScene(TriangleGltf(one_node), "design.gltf", dir_.string()).ok());
  // `levels` nodes, each the parent of the next.
  const auto chain = [](int levels) {
    std::string nodes = R"(,"nodes":[)";
    for (int i = 0; i + 1 < levels; ++i) nodes += R"({"mesh":0,"children":[)" + std::to_string(i + 1) + "]},";
    return nodes + R"({"mesh":0}])";
  };
  const Result<std::vector<NamedMesh>> deepest = DecodeGltfScene(TriangleGltf(chain(64)), "design.gltf", "");
  ASSERT_TRUE(deepest.ok()) << deepest.status().ToString();
  EXPECT_EQ(deepest->size(), 64u);
  const struct {
    std::string gltf;
    StatusCode code;
    const char* expected;
  } cases[] = {
      {TriangleGltf(R"(,"nodes":[{"mesh":0},{"children":[2]},{"mesh":0,"children":[1]}])"), StatusCode::kCorruptData,
       "cycle"},
      {TriangleGltf(R"(,"nodes":[{"mesh":0,"children":[0]}])"), StatusCode::kCorruptData,
       "nodes[0] is its own ancestor"},
      {TriangleGltf(R"(,"nodes":[{"children":[2]},{"children":[2]},{"mesh":0}])"), StatusCode::kCorruptData,
       "already a child of nodes[0]"},
      {TriangleGltf(chain(65)), StatusCode::kCorruptData, "nodes[64] lies deeper than 64"},
      {TriangleGltf(R"(,"scenes":[{"nodes":[1]}],"nodes":[{"children":[1]},{"mesh":0}])"), StatusCode::kCorruptData,
       "not a root node"},
      {TriangleGltf(one_node, "../design.bin"), StatusCode::kCorruptData, "\"..\""},
      {TriangleGltf(one_node, "parts/..%2F..%2Fdesign.bin"), StatusCode::kCorruptData, "\"..\""},
      {TriangleGltf(one_node, "/etc/design.bin"), StatusCode::kCorruptData, "absolute"},
      {TriangleGltf(one_node, "https://example.com/design.bin"), StatusCode::kUnsupported, "relative file names"},
      {TriangleGltf(one_node, "missing.bin"), StatusCode::kNotFound, "missing.bin"},
      {TriangleGltf(one_node, "data:application/octet-stream;base64,AAAA*AAA"), StatusCode::kCorruptData, "base64"},
      {TriangleGltf(one_node, "data:application/octet-stream;base64,AAA"), StatusCode::kCorruptData, "base64"},
      {TriangleGltf(one_node, "data:application/octet-stream;base64,AA=A"), StatusCode::kCorruptData, "base64"},
      {TriangleGltf(one_node, "data:text/plain,abc"), StatusCode::kUnsupported, "without base64"},
      {TriangleGltf(one_node, DataUri(TriangleBin().substr(0, 40))), StatusCode::kCorruptData, "byteLength 48"},
      {TriangleGltf(one_node, DataUri(TriangleBin()), R"(,"mode":0)"), StatusCode::kCorruptData,
       "no triangle mesh in the scene"},
      {TriangleGltf(""), StatusCode::kCorruptData, "no triangle mesh in the scene"},
      {TriangleGltf(R"(,"nodes":[{"mesh":0,"scale":[1e300,1,1]}])"), StatusCode::kCorruptData, "not a finite float"},
      {TriangleGltf(R"(,"nodes":[{"mesh":0,"matrix":[1,0,0,1,0,1,0,0,0,0,1,0,0,0,0,1]}])"), StatusCode::kCorruptData,
       "not affine"},
      {TriangleGltf(R"(,"nodes":[{"mesh":0,"rotation":[0,0,0,0]}])"), StatusCode::kCorruptData, "rotation"},
      {TriangleGltf(R"(,"nodes":[{"mesh":1}])"), StatusCode::kCorruptData, "meshes[1] missing"},
      {std::string("{\"asset\":"), StatusCode::kCorruptData, "byte 9"},
  };
  for (const auto& c : cases) {
    const Result<std::vector<NamedMesh>> scene = DecodeGltfScene(c.gltf, "design.gltf", dir_.string());
    ASSERT_FALSE(scene.ok()) << c.expected;
    EXPECT_EQ(scene.status().code(), c.code) << scene.status().ToString();
    EXPECT_NE(scene.status().message().find(c.expected), std::string::npos) << scene.status().message();
    EXPECT_EQ(scene.status().message().rfind("design.gltf", 0), 0u) << scene.status().message();
  }
  EXPECT_EQ(ReadGltfScene((dir_ / "absent.gltf").string()).status().code(), StatusCode::kNotFound);
  // DecodeGlb still refuses a buffer with a uri.
  EXPECT_EQ(DecodeGlb(MakeGlb(TriangleGltf(one_node), ""), "x.glb").status().code(), StatusCode::kUnsupported);
}

TEST(GlbTest, DamagedScenesAreNamedNeverCrash) {
  const Result<std::string> glb = EncodeGlbScene({{"a", testing::RandomMesh(12, 10, true, true, 1)},
                                                  {"b", testing::RandomMesh(9, 6, false, false, 2)},
                                                  {"c", testing::RandomMesh(5, 0, false, true, 3)}});
  ASSERT_TRUE(glb.ok());
  const std::string gltf = HierarchyGltf(DataUri(HierarchyBin()));
  for (const std::string* input : {&*glb, &gltf}) {
    ASSERT_TRUE(DecodeGltfScene(*input, "scene", "").ok());
    for (size_t cut = 0; cut < input->size(); ++cut) {
      const Result<std::vector<NamedMesh>> scene = DecodeGltfScene(input->substr(0, cut), "cut", "");
      ASSERT_FALSE(scene.ok()) << cut;
      EXPECT_EQ(scene.status().message().rfind("cut", 0), 0u) << scene.status().message();
    }
    for (size_t i = 0; i < input->size(); ++i) {
      std::string damaged = *input;
      damaged[i] = static_cast<char>(damaged[i] ^ 0x5A);
      const Result<std::vector<NamedMesh>> scene = DecodeGltfScene(damaged, "damaged", "");
      if (!scene.ok()) continue;
      for (const NamedMesh& element : *scene) {
        EXPECT_TRUE(ValidateMesh(element.mesh).ok()) << i;
        EXPECT_FALSE(element.mesh.triangles.empty()) << i;
      }
    }
  }
}

}  // namespace
}  // namespace reconar
