// WriteMeshFile / ReadMeshFile: the format follows the extension in any case, the options reach
// the PLY writer, and unknown extensions are refused naming the file and the extension.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/base/atomic_file.h"
#include "core/mesh/mesh_file.h"
#include "tests/core/mesh/mesh_test_util.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

class MeshFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTestDirectory(std::string("reconar_mesh_file_") +
                                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string dir_;
};

std::string Opening(const std::string& path, size_t length) {
  const Result<std::string> bytes = ReadFileToString(path);
  EXPECT_TRUE(bytes.ok()) << bytes.status().ToString();
  return bytes.ok() ? bytes->substr(0, length) : "";
}

TEST_F(MeshFileTest, ExtensionChoosesTheFormatInAnyCase) {
  const Mesh mesh = testing::RandomMesh(40, 60, true, true, 1);
  struct Case {
    const char* name;
    bool ply_ascii;
    const char* opening;
  };
  const Case cases[] = {
      {"a.ply", false, "ply\nformat binary_little_endian 1.0\n"},
      {"b.PLY", true, "ply\nformat ascii 1.0\n"},
      {"c.obj", false, "# reconar\n"},
      {"d.Obj", false, "# reconar\n"},
      {"e.glb", false, "glTF"},
      {"f.GLB", false, "glTF"},
      {"g.wrl", false, "#VRML V2.0 utf8\n"},
      {"h.WRL", false, "#VRML V2.0 utf8\n"},
  };
  for (const Case& c : cases) {
    const std::string path = dir_ + "/" + c.name;
    MeshFileOptions options;
    options.ply_ascii = c.ply_ascii;
    ASSERT_TRUE(WriteMeshFile(path, mesh, options).ok()) << c.name;
    EXPECT_EQ(Opening(path, std::string(c.opening).size()), c.opening) << c.name;
  }
}

TEST_F(MeshFileTest, ReadMeshFileReadsWhatWriteMeshFileWrote) {
  Mesh mesh = testing::RandomMesh(40, 60, true, true, 2);
  for (auto& colour : mesh.colors) colour[3] = 255;  // OBJ keeps no alpha
  for (const char* name : {"m.ply", "m.obj", "m.glb"}) {
    const std::string path = dir_ + "/" + name;
    ASSERT_TRUE(WriteMeshFile(path, mesh).ok()) << name;
    const Result<Mesh> read = ReadMeshFile(path);
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    testing::ExpectMeshesEqual(*read, mesh);
  }
}

TEST_F(MeshFileTest, UnknownExtensionsAreUnsupportedNamingFileAndExtension) {
  const Mesh mesh = testing::RandomMesh(4, 2, false, false, 3);
  for (const char* name : {"mesh.stl", "mesh", "mesh.ply.bak"}) {
    const std::string path = dir_ + "/" + name;
    const Status status = WriteMeshFile(path, mesh);
    EXPECT_EQ(status.code(), StatusCode::kUnsupported) << name;
    EXPECT_NE(status.message().find(path), std::string::npos) << status.ToString();
    EXPECT_FALSE(std::filesystem::exists(path));
    const Result<Mesh> read = ReadMeshFile(path);
    EXPECT_EQ(read.status().code(), StatusCode::kUnsupported) << name;
  }
  EXPECT_NE(WriteMeshFile(dir_ + "/mesh.stl", mesh).message().find("'.stl'"), std::string::npos);
  EXPECT_NE(WriteMeshFile(dir_ + "/mesh", mesh).message().find("no file extension"), std::string::npos);

  ASSERT_TRUE(WriteMeshFile(dir_ + "/mesh.wrl", mesh).ok());
  const Result<Mesh> vrml = ReadMeshFile(dir_ + "/mesh.wrl");
  EXPECT_EQ(vrml.status().code(), StatusCode::kUnsupported);
  EXPECT_NE(vrml.status().message().find("VRML"), std::string::npos);

  const Result<Mesh> missing = ReadMeshFile(dir_ + "/missing.glb");
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace reconar
