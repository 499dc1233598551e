// ReadPly / WritePly on files made in the test: round trips in both formats, every encoding,
// polygons, skipped properties and elements, and damaged inputs (a Status naming the file, no crash).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "core/base/atomic_file.h"
#include "core/mesh/mesh_io.h"
#include "tests/core/mesh/mesh_test_util.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

class PlyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("reconar_ply_" + std::to_string(::getpid())) / info->name();
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }

  std::string Write(const std::string& name, const std::string& bytes) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  fs::path dir_;
};

std::string BigEndian32(const void* value) {
  char bytes[4];
  std::memcpy(bytes, value, 4);
  uint32_t probe = 1;
  if (*reinterpret_cast<uint8_t*>(&probe) == 1) std::reverse(bytes, bytes + 4);
  return std::string(bytes, 4);
}

TEST_F(PlyTest, BinaryAndAsciiRoundTripsAreExact) {
  for (const bool with_normals : {false, true}) {
    for (const bool with_colors : {false, true}) {
      for (const bool with_triangles : {false, true}) {
        const Mesh mesh = testing::RandomMesh(257, with_triangles ? 500 : 0, with_normals, with_colors, 7);
        for (const PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
          const std::string path = (dir_ / "mesh.ply").string();
          ASSERT_TRUE(WritePly(path, mesh, format).ok());
          const Result<Mesh> read = ReadPly(path);
          ASSERT_TRUE(read.ok()) << read.status().ToString();
          testing::ExpectMeshesEqual(*read, mesh);
        }
      }
    }
  }
}

TEST_F(PlyTest, ExtremeFloatsRoundTripInAscii) {
  Mesh mesh;
  mesh.positions = {{1e-30f, -3.4e38f, 0.1f}, {1.0f / 3.0f, 16777217.0f, -0.0f}, {1.17549435e-38f, 7.0f, 1e30f}};
  mesh.triangles = {{0, 1, 2}};
  const std::string path = (dir_ / "extreme.ply").string();
  ASSERT_TRUE(WritePly(path, mesh, PlyFormat::kAscii).ok());
  const Result<Mesh> read = ReadPly(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  testing::ExpectMeshesEqual(*read, mesh);
}

TEST_F(PlyTest, BigEndianDoublesFloatColoursAndQuads) {
  // Doubles for positions, float colours, an extra short property, a quad and a pentagon, uint
  // counts, CRLF line ends in the header.
  const std::string vertex_header =
      "ply\r\nformat binary_big_endian 1.0\r\ncomment made by hand\r\nelement vertex 5\r\n"
      "property double x\r\nproperty double y\r\nproperty double z\r\nproperty short flags\r\n"
      "property float red\r\nproperty float green\r\nproperty float blue\r\n";
  const std::string header =
      vertex_header + "element face 2\r\nproperty uint material\r\nproperty list uint int vertex_index\r\nend_header\r\n";
  std::string body;
  const auto append_double = [&](double v) {
    char bytes[8];
    std::memcpy(bytes, &v, 8);
    uint32_t probe = 1;
    if (*reinterpret_cast<uint8_t*>(&probe) == 1) std::reverse(bytes, bytes + 8);
    body.append(bytes, 8);
  };
  const auto append_float = [&](float v) { body += BigEndian32(&v); };
  const auto append_int = [&](int32_t v) { body += BigEndian32(&v); };
  for (int i = 0; i < 5; ++i) {
    append_double(0.5 * i);
    append_double(-1.25 * i);
    append_double(1e-3 * i);
    body += std::string("\x01\x02", 2);
    append_float(0.0f);
    append_float(1.0f);
    append_float(0.5f);
  }
  append_int(9);  // material of face 0
  append_int(4);
  for (const int32_t v : {0, 1, 2, 3}) append_int(v);
  append_int(9);
  append_int(5);
  for (const int32_t v : {4, 3, 2, 1, 0}) append_int(v);

  // A scalar named vertex_index is not a polygon: the file is corrupt.
  const std::string scalar_header =
      vertex_header + "element face 2\r\nproperty uint vertex_index\r\nproperty list uint int vertex_index\r\nend_header\r\n";
  const Result<Mesh> rejected = ReadPly(Write("scalar.ply", scalar_header + body));
  ASSERT_FALSE(rejected.ok());
  EXPECT_EQ(rejected.status().code(), StatusCode::kCorruptData);

  const Result<Mesh> read = ReadPly(Write("big.ply", header + body));
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->positions.size(), 5u);
  EXPECT_EQ(read->positions[3], Eigen::Vector3f(1.5f, -3.75f, 0.003f));
  ASSERT_EQ(read->colors.size(), 5u);
  EXPECT_EQ(read->colors[2], (std::array<uint8_t, 4>{0, 255, 128, 255}));
  EXPECT_TRUE(read->normals.empty());
  const std::vector<std::array<uint32_t, 3>> expected = {{0, 1, 2}, {0, 2, 3}, {4, 3, 2}, {4, 2, 1}, {4, 1, 0}};
  EXPECT_EQ(read->triangles, expected);
}

TEST_F(PlyTest, AsciiSkipsOtherElementsAndProperties) {
  const std::string text =
      "ply\nformat ascii 1.0\nobj_info scanner\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty float confidence\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nproperty uchar alpha\nproperty float nx\nproperty float ny\nproperty float nz\n"
      "element range_grid 3\nproperty list uchar int vertex_indices\n"
      "element face 3\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\n"
      "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
      "0 0 0 0.5 10 20 30 40 0 0 1\n1 0 0 0.5 11 21 31 41 0 0 1\n0 1 0 0.5 12 22 32 42 0 0 1\n"
      "1 1 +0 0.5 13 23 33 43 0 0 1\n"
      "0\n1 2\n2 0 3\n"
      "3 0 1 2 6 0 0 1 0 0 1\n2 0 1 0\n3 1 3 2 0\n"
      "0 1\n";
  const Result<Mesh> read = ReadPly(Write("skip.ply", text));
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->positions.size(), 4u);
  EXPECT_EQ(read->colors[3], (std::array<uint8_t, 4>{13, 23, 33, 43}));
  EXPECT_EQ(read->normals[1], Eigen::Vector3f(0, 0, 1));
  // The two-corner face is skipped.
  const std::vector<std::array<uint32_t, 3>> expected = {{0, 1, 2}, {1, 3, 2}};
  EXPECT_EQ(read->triangles, expected);
}

// Found by design_fuzz: such an element's 2^32 - 1 empty rows took minutes to skip one by one.
TEST_F(PlyTest, AnElementWithoutPropertiesIsSkippedAtOnce) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement edge 4294967295\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "element material 9223372036854775807\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const Result<Mesh> read = ReadPly(Write("empty_rows.ply", text));
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->positions.size(), 3u);
  EXPECT_EQ(read->triangles.size(), 1u);
}

TEST_F(PlyTest, OutOfRangeIndexNamesFileAndFace) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 3\n";
  const std::string path = Write("range.ply", text);
  const Result<Mesh> read = ReadPly(path);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(read.status().message().find(path), std::string::npos) << read.status().message();
  EXPECT_NE(read.status().message().find("face 1"), std::string::npos) << read.status().message();
  EXPECT_NE(read.status().message().find("index 3"), std::string::npos) << read.status().message();

  const Result<Mesh> negative = ReadPly(Write("negative.ply", text.substr(0, text.size() - 6) + "0 -1 2\n"));
  ASSERT_FALSE(negative.ok());
  EXPECT_NE(negative.status().message().find("index -1"), std::string::npos) << negative.status().message();
}

TEST_F(PlyTest, TruncatedFilesAreCorruptData) {
  Mesh mesh = testing::RandomMesh(100, 150, true, true, 3);
  for (const PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
    const std::string full_path = (dir_ / "full.ply").string();
    ASSERT_TRUE(WritePly(full_path, mesh, format).ok());
    const std::string bytes = *ReadFileToString(full_path);
    // Cut at many places: inside the header, the vertices and the faces. (An ASCII cut inside the
    // last line can leave a shorter number that still parses, so ASCII cuts stop before it.)
    const size_t limit = format == PlyFormat::kAscii ? bytes.rfind('\n', bytes.size() - 2) + 1 : bytes.size();
    for (size_t cut = 0; cut < limit; cut += 1 + bytes.size() / 97) {
      const std::string path = Write("cut.ply", bytes.substr(0, cut));
      const Result<Mesh> read = ReadPly(path);
      ASSERT_FALSE(read.ok()) << "cut at " << cut;
      EXPECT_EQ(read.status().code(), StatusCode::kCorruptData) << read.status().ToString();
      EXPECT_NE(read.status().message().find(path), std::string::npos) << read.status().message();
    }
  }
}

TEST_F(PlyTest, HugeDeclaredCountsFailBeforeAllocating) {
  const std::string text =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n" + std::string(24, '\0');
  const Result<Mesh> read = ReadPly(Write("huge.ply", text));
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(read.status().message().find("truncated"), std::string::npos) << read.status().message();
}

// Found by design_fuzz: NaN and infinity in binary or ascii, a double beyond float's range.
TEST_F(PlyTest, PositionsThatAreNotFiniteFloatsNameFileAndVertex) {
  const auto binary = [](float x_of_vertex_1) {
    std::string text =
        "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n";
    for (const float value : {0.0f, 0.0f, 0.0f, x_of_vertex_1, 0.0f, 0.0f}) text += BigEndian32(&value);
    return text;
  };
  const std::string ascii_header =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty double y\nproperty float z\n"
      "end_header\n";
  const struct {
    const char* name;
    std::string text;
    const char* message_part;
  } cases[] = {
      {"binary_nan", binary(std::numeric_limits<float>::quiet_NaN()), "vertex 1: x is not a finite float"},
      {"binary_infinity", binary(-std::numeric_limits<float>::infinity()), "vertex 1: x is not a finite float"},
      {"ascii_nan", ascii_header + "0 0 0\n1 2 nan\n", "vertex 1: z is not a finite float"},
      {"ascii_beyond_float", ascii_header + "0 1e39 0\n1 2 3\n", "vertex 0: y is not a finite float"},
  };
  for (const auto& c : cases) {
    const std::string path = Write(std::string(c.name) + ".ply", c.text);
    const Result<Mesh> read = ReadPly(path);
    ASSERT_FALSE(read.ok()) << c.name;
    EXPECT_EQ(read.status().code(), StatusCode::kCorruptData) << c.name;
    EXPECT_NE(read.status().message().find(path), std::string::npos) << read.status().message();
    EXPECT_NE(read.status().message().find(c.message_part), std::string::npos) << read.status().message();
  }
}

TEST_F(PlyTest, BadHeadersAndValues) {
  const std::string vertex_header = "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
  const struct {
    const char* name;
    std::string text;
    StatusCode code;
  } cases[] = {
      {"empty", "", StatusCode::kCorruptData},
      {"magic", "plx\nformat ascii 1.0\nend_header\n", StatusCode::kCorruptData},
      {"no_end", "ply\nformat ascii 1.0\n" + vertex_header, StatusCode::kCorruptData},
      {"no_format", "ply\n" + vertex_header + "end_header\n0 0 0\n", StatusCode::kCorruptData},
      {"version", "ply\nformat ascii 2.0\n" + vertex_header + "end_header\n0 0 0\n", StatusCode::kCorruptData},
      {"type", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n", StatusCode::kCorruptData},
      {"no_vertex", "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
       StatusCode::kCorruptData},
      {"no_z", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
       StatusCode::kCorruptData},
      {"word", "ply\nformat ascii 1.0\n" + vertex_header + "end_header\n0 zero 0\n", StatusCode::kCorruptData},
      {"uchar_range", "ply\nformat ascii 1.0\n" + vertex_header +
           "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n300 0 0 0\n",
       StatusCode::kCorruptData},
      {"short_colour", "ply\nformat ascii 1.0\n" + vertex_header +
           "property ushort red\nproperty ushort green\nproperty ushort blue\nend_header\n0 0 0 1 2 3\n",
       StatusCode::kUnsupported},
  };
  for (const auto& c : cases) {
    const std::string path = Write(std::string(c.name) + ".ply", c.text);
    const Result<Mesh> read = ReadPly(path);
    ASSERT_FALSE(read.ok()) << c.name;
    EXPECT_EQ(read.status().code(), c.code) << c.name << ": " << read.status().ToString();
    EXPECT_NE(read.status().message().find(path), std::string::npos) << read.status().message();
  }
  EXPECT_EQ(ReadPly((dir_ / "missing.ply").string()).status().code(), StatusCode::kNotFound);
}

TEST_F(PlyTest, WriterRejectsInconsistentMeshesAndUnwritablePaths) {
  Mesh mesh = testing::RandomMesh(10, 5, true, true, 1);
  mesh.triangles[4][1] = 10;
  const std::string path = (dir_ / "bad.ply").string();
  const Status bad_index = WritePly(path, mesh);
  EXPECT_EQ(bad_index.code(), StatusCode::kInvalidArgument) << bad_index.ToString();
  EXPECT_NE(bad_index.message().find("triangle 4"), std::string::npos) << bad_index.message();
  mesh.triangles[4][1] = 9;
  mesh.normals.pop_back();
  EXPECT_EQ(WritePly(path, mesh).code(), StatusCode::kInvalidArgument);
  EXPECT_FALSE(fs::exists(path));
  mesh.normals.clear();
  const std::string unwritable = (dir_ / "no_such_dir" / "m.ply").string();
  const Status io = WritePly(unwritable, mesh);
  EXPECT_EQ(io.code(), StatusCode::kIoError);
  EXPECT_NE(io.message().find(unwritable), std::string::npos) << io.message();
}

}  // namespace
}  // namespace reconar
