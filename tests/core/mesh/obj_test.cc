// WriteObj / ReadObj: exact round trips, files in the forms other programs write (the OBJ
// specification's corner forms, negative indices, polygons, separately indexed normals) and damaged
// inputs (a Status naming the file and line, no crash).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "core/base/atomic_file.h"
#include "core/mesh/obj_io.h"
#include "tests/core/mesh/mesh_test_util.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

class ObjTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTestDirectory(std::string("reconar_obj_") +
                                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }

  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  std::string dir_;
};

// OBJ carries no alpha: colours come back opaque.
Mesh Opaque(Mesh mesh) {
  for (auto& colour : mesh.colors) colour[3] = 255;
  return mesh;
}

TEST_F(ObjTest, RoundTripsAreExact) {
  for (const bool with_normals : {false, true}) {
    for (const bool with_colors : {false, true}) {
      for (const bool with_triangles : {false, true}) {
        SCOPED_TRACE(::testing::Message() << "normals " << with_normals << " colours " << with_colors
                                          << " triangles " << with_triangles);
        const Mesh mesh = testing::RandomMesh(257, with_triangles ? 500 : 0, with_normals, with_colors, 11);
        const std::string path = dir_ + "/mesh.obj";
        ASSERT_TRUE(WriteObj(path, mesh).ok());
        const Result<Mesh> read = ReadObj(path);
        ASSERT_TRUE(read.ok()) << read.status().ToString();
        testing::ExpectMeshesEqual(*read, Opaque(mesh));
      }
    }
  }
}

TEST_F(ObjTest, WritesTheDocumentedLines) {
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0.5f, -2.25f}};
  mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  mesh.colors = {{255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 128}};
  mesh.triangles = {{0, 1, 2}};
  const std::string path = dir_ + "/triangle.obj";
  ASSERT_TRUE(WriteObj(path, mesh).ok());
  const Result<std::string> text = ReadFileToString(path);
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(*text,
            "# reconar\n# 3 vertices, 1 triangles\n"
            "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 0.5 -2.25 0 0 1\n"
            "vn 0 0 1\nvn 0 0 1\nvn 0 0 1\n"
            "f 1//1 2//2 3//3\n");
}

TEST_F(ObjTest, TexturedWritesTexcoordsAndItsMaterialLibrary) {
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0.5f, -2.25f}};
  mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  mesh.texcoords = {{0, 0}, {1, 0.25f}, {0.5f, 1}};
  mesh.triangles = {{0, 1, 2}};
  const std::string path = dir_ + "/textured.obj";
  ASSERT_TRUE(WriteTexturedObj(path, mesh, {{0, "textured.png"}}).ok());
  const Result<std::string> text = ReadFileToString(path);
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(*text,
            "# reconar\n# 3 vertices, 1 triangles\nmtllib textured.mtl\n"
            "v 0 0 0\nv 1 0 0\nv 0 0.5 -2.25\n"
            "vn 0 0 1\nvn 0 0 1\nvn 0 0 1\n"
            "vt 0 1\nvt 1 0.75\nvt 0.5 0\nusemtl texture\n"
            "f 1/1/1 2/2/2 3/3/3\n");
  const Result<std::string> library = ReadFileToString(dir_ + "/textured.mtl");
  ASSERT_TRUE(library.ok());
  EXPECT_NE(library->find("newmtl texture\n"), std::string::npos);
  EXPECT_NE(library->find("map_Kd textured.png\n"), std::string::npos);
  // Our reader (and every other) takes it back.
  const Result<Mesh> read = ReadObj(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->positions, mesh.positions);
  EXPECT_EQ(read->triangles, mesh.triangles);

  // A second page: its faces after their material.
  mesh.triangles.push_back({2, 1, 0});
  ASSERT_TRUE(WriteTexturedObj(path, mesh, {{0, "textured.png"}, {1, "textured_1.png"}}).ok());
  const Result<std::string> paged = ReadFileToString(path);
  ASSERT_TRUE(paged.ok());
  EXPECT_NE(paged->find("usemtl texture\nf 1/1/1 2/2/2 3/3/3\nusemtl texture_1\nf 3/3/3 2/2/2 1/1/1\n"),
            std::string::npos);
  const Result<std::string> paged_library = ReadFileToString(dir_ + "/textured.mtl");
  ASSERT_TRUE(paged_library.ok());
  EXPECT_NE(paged_library->find("newmtl texture_1\n"), std::string::npos);
  EXPECT_NE(paged_library->find("map_Kd textured_1.png\n"), std::string::npos);
  EXPECT_EQ(WriteTexturedObj(dir_ + "/late.obj", mesh, {{1, "textured.png"}}).code(), StatusCode::kInvalidArgument);

  mesh.texcoords.clear();
  EXPECT_EQ(WriteTexturedObj(dir_ + "/none.obj", mesh, {{0, "none.png"}}).code(), StatusCode::kInvalidArgument);
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/none.obj"));
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/late.obj"));
}

// The corner forms of the OBJ specification (Wavefront, Appendix B1): v, v/vt, v//vn, v/vt/vn,
// with negative (relative) indices, a quad, comments and statements we skip.
TEST_F(ObjTest, ReadsEveryCornerFormAndRelativeIndices) {
  const std::string path = Write("forms.obj",
                                 "# a unit square as a quad, then the same square again as two triangles\n"
                                 "mtllib square.mtl\no square\ng front\ns off\n"
                                 "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0   # trailing comment\n"
                                 "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                 "vn 0 0 1\n"
                                 "usemtl grey\n"
                                 "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
                                 "f -4//-1 -3//-1 -2//-1\n"
                                 "f 1/1 3/3 4/4\r\n"
                                 "l 1 2\np 3\n");
  const Result<Mesh> mesh = ReadObj(path);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  EXPECT_EQ(mesh->positions.size(), 4u);
  const std::vector<std::array<uint32_t, 3>> expected = {{0, 1, 2}, {0, 2, 3}, {0, 1, 2}, {0, 2, 3}};
  EXPECT_EQ(mesh->triangles, expected);
  // Every vertex is named with normal 1 by some corner.
  ASSERT_EQ(mesh->normals.size(), 4u);
  for (const Eigen::Vector3f& n : mesh->normals) EXPECT_EQ(n, Eigen::Vector3f(0, 0, 1));
  EXPECT_TRUE(mesh->colors.empty());
}

TEST_F(ObjTest, NormalsIndexedApartFromPositionsBecomePerVertex) {
  const std::string path = Write("normals.obj",
                                 "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                 "vn 1 0 0\nvn 0 0 1\n"
                                 "f 1//2 2//2 3//2\n");
  const Result<Mesh> mesh = ReadObj(path);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  ASSERT_EQ(mesh->normals.size(), 3u);
  for (const Eigen::Vector3f& n : mesh->normals) EXPECT_EQ(n, Eigen::Vector3f(0, 0, 1));

  // A vertex with two different normals (a hard edge) cannot keep one: no normals.
  const std::string hard = Write("hard.obj",
                                 "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                 "vn 0 0 -1\nvn 0 -1 0\n"
                                 "f 1//1 3//1 2//1\nf 1//2 2//2 4//2\n");
  const Result<Mesh> hard_mesh = ReadObj(hard);
  ASSERT_TRUE(hard_mesh.ok()) << hard_mesh.status().ToString();
  EXPECT_EQ(hard_mesh->triangles.size(), 2u);
  EXPECT_TRUE(hard_mesh->normals.empty());
}

TEST_F(ObjTest, ReadsWeightsAndColours) {
  const std::string path = Write("colours.obj", "v 1 2 3 1.0\nv 4 5 6 1\nv 0 0 0\n");
  const Result<Mesh> weights = ReadObj(path);
  ASSERT_TRUE(weights.ok()) << weights.status().ToString();
  EXPECT_EQ(weights->positions[1], Eigen::Vector3f(4, 5, 6));
  EXPECT_TRUE(weights->colors.empty());

  const Result<Mesh> coloured = ReadObj(Write("rgb.obj", "v 0 0 0 1 0.5 0\nv 1 0 0 -1 2 +0.2\n"));
  ASSERT_TRUE(coloured.ok()) << coloured.status().ToString();
  const std::vector<std::array<uint8_t, 4>> expected = {{255, 128, 0, 255}, {0, 255, 51, 255}};
  EXPECT_EQ(coloured->colors, expected);

  // Colours on some vertices only are dropped.
  const Result<Mesh> partly = ReadObj(Write("partly.obj", "v 0 0 0 1 0.5 0\nv 1 0 0\n"));
  ASSERT_TRUE(partly.ok());
  EXPECT_TRUE(partly->colors.empty());
}

TEST_F(ObjTest, DamagedFilesGiveStatusesNamingFileAndLine) {
  struct Case {
    const char* text;
    StatusCode code;
    const char* message_part;
  };
  const Case cases[] = {
      {"", StatusCode::kCorruptData, "no vertex"},
      {"# only a comment\nvt 0 0\n", StatusCode::kCorruptData, "no vertex"},
      {"v 0 0\n", StatusCode::kCorruptData, "line 1: 'v' needs 3"},
      {"v 0 0 0\nv 1 x 0\n", StatusCode::kCorruptData, "line 2: malformed number 'x'"},
      // Numbers from_chars reads but no coordinate is (found by design_fuzz).
      {"v 0 0 0\nv 0 4 nan\nf 1 2 1\n", StatusCode::kCorruptData, "line 2: malformed number 'nan'"},
      {"v 0 0 0\nvn 0 -inf 1\n", StatusCode::kCorruptData, "line 2: malformed number '-inf'"},
      {"v 0 0 0\nvn 0 0\n", StatusCode::kCorruptData, "line 2: 'vn' needs 3"},
      {"v 0 0 0\nf 1 1\n", StatusCode::kCorruptData, "at least 3 corners"},
      {"v 0 0 0\nv 1 0 0\nf 1 2 3\n", StatusCode::kCorruptData, "line 3: vertex index 3 out of range [1, 2]"},
      {"v 0 0 0\nf 0 1 1\n", StatusCode::kCorruptData, "bad vertex index '0'"},
      {"v 0 0 0\nf -2 1 1\n", StatusCode::kCorruptData, "relative vertex index -2"},
      {"v 0 0 0\nf 1//1 1 1\n", StatusCode::kCorruptData, "normal index 1 out of range"},
      {"v 0 0 0\nf 1/a/ 1 1\nf 1/1/1/1 1 1\n", StatusCode::kCorruptData, "bad normal index ''"},
      {"v 0 0 0\nf 1//1/1 1 1\n", StatusCode::kCorruptData, "bad normal index '1/1'"},
  };
  int k = 0;
  for (const Case& c : cases) {
    const std::string path = Write("bad" + std::to_string(k++) + ".obj", c.text);
    const Result<Mesh> mesh = ReadObj(path);
    ASSERT_FALSE(mesh.ok()) << c.text;
    EXPECT_EQ(mesh.status().code(), c.code) << c.text;
    EXPECT_NE(mesh.status().message().find(path), std::string::npos) << mesh.status().ToString();
    EXPECT_NE(mesh.status().message().find(c.message_part), std::string::npos) << mesh.status().ToString();
  }
  const Result<Mesh> missing = ReadObj(dir_ + "/missing.obj");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
}

TEST_F(ObjTest, RefusesInconsistentOrNonFiniteMeshesAndWritesNothing) {
  Mesh mesh = testing::RandomMesh(10, 5, true, false, 3);
  mesh.triangles.push_back({0, 1, 10});
  const std::string path = dir_ + "/refused.obj";
  EXPECT_EQ(WriteObj(path, mesh).code(), StatusCode::kInvalidArgument);
  mesh.triangles.pop_back();
  mesh.normals[4].x() = std::numeric_limits<float>::quiet_NaN();
  const Status status = WriteObj(path, mesh);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("vertex 4 has a non-finite normal"), std::string::npos) << status.ToString();
  EXPECT_FALSE(ReadFileToString(path).ok());
}

// A design's elements: faces split by their group ("g" or "o", the latest), each group with only
// its own vertices; a group named again continues; faces before any group are "default".
TEST_F(ObjTest, GroupsSplitIntoNamedMeshes) {
  const std::string path = Write("design.obj",
                                 "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nv 6 5 5\nv 6 6 5\n"
                                 "f 1 2 3\n"
                                 "g wall north  # a comment\n"
                                 "f 1 3 4\n"
                                 "o door\n"
                                 "f 5 6 7\n"
                                 "g wall north\n"
                                 "f 2 3 4\n");
  const Result<std::vector<NamedMesh>> groups = ReadObjGroups(path);
  ASSERT_TRUE(groups.ok()) << groups.status().message();
  ASSERT_EQ(groups->size(), 3u);
  EXPECT_EQ((*groups)[0].name, "default");
  EXPECT_EQ((*groups)[1].name, "wall north");
  EXPECT_EQ((*groups)[2].name, "door");
  EXPECT_EQ((*groups)[0].mesh.triangles.size(), 1u);
  EXPECT_EQ((*groups)[1].mesh.triangles.size(), 2u);
  EXPECT_EQ((*groups)[1].mesh.positions.size(), 4u);  // vertices 1..4, nothing of the door
  const Mesh& door = (*groups)[2].mesh;
  ASSERT_EQ(door.positions.size(), 3u);
  EXPECT_EQ(door.positions[door.triangles[0][1]], Eigen::Vector3f(6, 5, 5));
  EXPECT_TRUE(ValidateMesh(door).ok());
}

TEST_F(ObjTest, GroupsOfAFileWithoutFacesIsAnError) {
  const std::string path = Write("points.obj", "v 0 0 0\nv 1 0 0\ng a\n");
  const Result<std::vector<NamedMesh>> groups = ReadObjGroups(path);
  ASSERT_FALSE(groups.ok());
  EXPECT_NE(groups.status().message().find("points.obj"), std::string::npos);
}

}  // namespace
}  // namespace reconar
