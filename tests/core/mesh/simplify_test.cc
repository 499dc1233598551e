// Quadric-error simplification (core/mesh/simplify.h) against analytic shapes: a finely
// tessellated sphere stays a closed, outward-facing manifold on the sphere; a flat sheet keeps its
// plane, its border and its area; colours follow; bad input is refused.
#include "core/mesh/simplify.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <utility>

#include "tests/core/mesh/mesh_test_util.h"

namespace reconar {
namespace {

// An icosahedron subdivided `levels` times, vertices pushed onto the unit sphere.
Mesh Icosphere(int levels) {
  const float g = (1.0f + std::sqrt(5.0f)) / 2.0f;
  Mesh mesh;
  mesh.positions = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                    {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                    {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& p : mesh.positions) p.normalize();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> middle;
    const auto mid = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto found = middle.find(key);
      if (found != middle.end()) return found->second;
      mesh.positions.push_back((mesh.positions[a] + mesh.positions[b]).normalized());
      return middle[key] = static_cast<uint32_t>(mesh.positions.size() - 1);
    };
    std::vector<std::array<uint32_t, 3>> finer;
    for (const auto& t : mesh.triangles) {
      const uint32_t ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      finer.push_back({t[0], ab, ca});
      finer.push_back({t[1], bc, ab});
      finer.push_back({t[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    mesh.triangles = std::move(finer);
  }
  return mesh;
}

// A unit square sheet of n x n cells in z = 0, coloured by x.
Mesh Sheet(int n) {
  Mesh mesh = testing::GridMesh(n, 1.0f, 0.0f);
  for (const Eigen::Vector3f& p : mesh.positions) {
    mesh.colors.push_back({static_cast<uint8_t>(std::lround(255 * p.x())), 0, 0, 255});
  }
  return mesh;
}

double Area(const Mesh& mesh) {
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>(), b = mesh.positions[t[1]].cast<double>(),
                          c = mesh.positions[t[2]].cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

// Edge -> number of faces using it with each orientation.
std::map<std::pair<uint32_t, uint32_t>, int> DirectedEdges(const Mesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
  }
  return edges;
}

TEST(SimplifyTest, SphereStaysAClosedOutwardManifoldOnTheSphere) {
  Mesh mesh = Icosphere(5);  // 20,480 faces
  ComputeVertexNormals(&mesh);
  SimplifyOptions options;
  options.target_faces = 2000;
  auto report = SimplifyMesh(options, &mesh);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->faces_before, 20480u);
  EXPECT_LE(mesh.triangles.size(), 2000u);
  EXPECT_GE(mesh.triangles.size(), 1990u);
  EXPECT_EQ(report->faces_after, mesh.triangles.size());
  ASSERT_TRUE(ValidateMesh(mesh).ok());
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());

  // Closed and consistently oriented: every directed edge once, its reverse once.
  const auto edges = DirectedEdges(mesh);
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 1);
    const auto reverse = edges.find({edge.second, edge.first});
    ASSERT_NE(reverse, edges.end());
  }
  const long euler = static_cast<long>(mesh.positions.size()) - static_cast<long>(edges.size() / 2) +
                     static_cast<long>(mesh.triangles.size());
  EXPECT_EQ(euler, 2);
  double worst_vertex = 0.0, worst_centroid = 0.0;
  for (const auto& p : mesh.positions) worst_vertex = std::max(worst_vertex, std::abs(p.norm() - 1.0));
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
    const Eigen::Vector3f centroid = (a + b + c) / 3.0f;
    EXPECT_GT((b - a).cross(c - a).dot(centroid), 0.0f) << "a face turned inwards";
    worst_centroid = std::max(worst_centroid, 1.0 - centroid.norm());
  }
  std::printf("sphere: %zu -> %zu faces, %zu collapses, worst |r - 1| vertex %.5f, face centre %.5f\n",
              report->faces_before, report->faces_after, report->collapses, worst_vertex, worst_centroid);
  // 2,000 faces of about 0.0063 sr: edges near 0.12, so a face's centre sits ~0.003 inside.
  EXPECT_LT(worst_vertex, 0.005);
  EXPECT_LT(worst_centroid, 0.02);
}

TEST(SimplifyTest, FlatSheetKeepsItsPlaneBorderAreaAndColours) {
  Mesh mesh = Sheet(40);  // 3,200 faces
  SimplifyOptions options;
  options.target_faces = 40;
  auto report = SimplifyMesh(options, &mesh);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_LE(mesh.triangles.size(), 40u);
  EXPECT_NEAR(Area(mesh), 1.0, 1e-5);
  EXPECT_LT(report->max_collapse_error, 1e-9);  // collinear and coplanar collapses cost nothing
  ASSERT_EQ(mesh.colors.size(), mesh.positions.size());
  int corners = 0;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const Eigen::Vector3f& p = mesh.positions[v];
    EXPECT_NEAR(p.z(), 0.0f, 1e-7f);
    EXPECT_GE(p.x(), -1e-6f);
    EXPECT_LE(p.x(), 1.0f + 1e-6f);
    corners += (std::abs(p.x() - std::round(p.x())) < 1e-6f && std::abs(p.y() - std::round(p.y())) < 1e-6f) ? 1 : 0;
    // Red was 255 x at every vertex; a vertex moved along an edge carries the interpolated colour.
    EXPECT_NEAR(mesh.colors[v][0], 255.0f * p.x(), 255.0f / 40 + 1.0f) << p.transpose();
  }
  EXPECT_EQ(corners, 4);
  std::printf("sheet: %zu -> %zu faces, %zu vertices, area %.7f\n", report->faces_before, report->faces_after,
              mesh.positions.size(), Area(mesh));
  // Every face still faces +z.
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f n = (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    EXPECT_GT(n.z(), 0.0f);
  }
}

TEST(SimplifyTest, ErrorBoundStopsEarlyAndSmallMeshesAreLeftAlone) {
  Mesh sphere = Icosphere(3);
  SimplifyOptions options;
  options.target_faces = 4;
  options.max_error = 1e-6;
  auto report = SimplifyMesh(options, &sphere);
  ASSERT_TRUE(report.ok());
  EXPECT_GT(sphere.triangles.size(), 100u) << "a curved surface cannot lose most faces within 1e-6";
  EXPECT_LE(report->max_collapse_error, 1e-6);

  Mesh small = Icosphere(0);
  const Mesh before = small;
  options.target_faces = 100;
  options.max_error = std::numeric_limits<double>::infinity();
  report = SimplifyMesh(options, &small);
  ASSERT_TRUE(report.ok());
  EXPECT_EQ(small.triangles, before.triangles);
  EXPECT_EQ(report->collapses, 0u);
}

TEST(SimplifyTest, BadOptionsAndMeshesAreRefused) {
  Mesh mesh = Icosphere(1);
  SimplifyOptions options;
  EXPECT_EQ(SimplifyMesh(options, &mesh).status().code(), StatusCode::kInvalidArgument);  // no target
  options.target_faces = 10;
  options.min_normal_cosine = 2.0;
  EXPECT_EQ(SimplifyMesh(options, &mesh).status().code(), StatusCode::kInvalidArgument);
  options.min_normal_cosine = 0.2;
  mesh.triangles.push_back({0, 1, 99999});
  EXPECT_EQ(SimplifyMesh(options, &mesh).status().code(), StatusCode::kInvalidArgument);
}

TEST(SimplifyTest, FaceBudgetSimplifiesOnlyMeshesOverIt) {
  Mesh sphere = Icosphere(3);
  Mesh by_options = sphere;
  auto report = SimplifyToFaceBudget(200, &sphere);
  ASSERT_TRUE(report.ok());
  EXPECT_TRUE(report->simplified);
  EXPECT_LE(sphere.triangles.size(), 200u);
  SimplifyOptions options;
  options.target_faces = 200;
  ASSERT_TRUE(SimplifyMesh(options, &by_options).ok());
  EXPECT_EQ(sphere.triangles, by_options.triangles);  // the default options
  EXPECT_EQ(sphere.positions, by_options.positions);

  // Within the budget, or no budget: untouched, not even validated, and an all-zero report.
  Mesh broken = Icosphere(1);
  broken.triangles.push_back({0, 1, 99999});
  const Mesh before = broken;
  for (const size_t budget : {size_t{0}, broken.triangles.size()}) {
    report = SimplifyToFaceBudget(budget, &broken);
    ASSERT_TRUE(report.ok());
    EXPECT_FALSE(report->simplified);
    EXPECT_EQ(report->faces_before, 0u);
    EXPECT_EQ(broken.triangles, before.triangles);
  }
  EXPECT_EQ(SimplifyToFaceBudget(10, &broken).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace reconar
