// ValidateMesh and ComputeVertexNormals on meshes whose answers are known in closed form.
#include "core/mesh/mesh.h"

#include <gtest/gtest.h>

namespace reconar {
namespace {

TEST(MeshTest, ValidateMeshNamesTheFirstProblem) {
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  EXPECT_TRUE(ValidateMesh(mesh).ok());
  mesh.normals.resize(2);
  EXPECT_EQ(ValidateMesh(mesh).code(), StatusCode::kInvalidArgument);
  mesh.normals.clear();
  mesh.colors.resize(4);
  EXPECT_EQ(ValidateMesh(mesh).code(), StatusCode::kInvalidArgument);
  mesh.colors.clear();
  mesh.triangles.push_back({2, 3, 0});
  const Status status = ValidateMesh(mesh);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("triangle 1"), std::string::npos) << status.message();
}

TEST(MeshTest, VertexNormalsOfAUnitCubeCornerAndAnIsolatedVertex) {
  // Two counter-clockwise triangles of the z=0 plane facing +z, one of the x=0 plane facing +x
  // (twice the area), and a vertex no triangle uses.
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 2}, {5, 5, 5}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}};
  ComputeVertexNormals(&mesh);
  ASSERT_EQ(mesh.normals.size(), 6u);
  EXPECT_TRUE(mesh.normals[1].isApprox(Eigen::Vector3f(0, 0, 1)));
  EXPECT_TRUE(mesh.normals[2].isApprox(Eigen::Vector3f(0, 0, 1)));
  EXPECT_TRUE(mesh.normals[4].isApprox(Eigen::Vector3f(1, 0, 0)));
  // Vertices 0 and 3: area 0.5 (+z) twice / once and area 1 (+x) once.
  EXPECT_TRUE(mesh.normals[0].isApprox(Eigen::Vector3f(1, 0, 1).normalized()));
  EXPECT_TRUE(mesh.normals[3].isApprox(Eigen::Vector3f(1, 0, 0.5f).normalized()));
  EXPECT_EQ(mesh.normals[5], Eigen::Vector3f(0, 0, 1));
  for (const Eigen::Vector3f& n : mesh.normals) EXPECT_NEAR(n.norm(), 1.0f, 1e-6f);
}

}  // namespace
}  // namespace reconar
