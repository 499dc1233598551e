// IFC through IFC++ (core/compare/ifc_import.h) on a hand-written IFC4 file (data/wall_and_slab.ifc):
// a wall, a 4000 x 200 mm rectangle extruded 2500 mm and placed 1000 mm along x, and a 6000 x
// 5000 x 200 mm floor slab, in millimetres; the site, building and storey have no geometry.
#include "core/compare/ifc_import.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace reconar {
namespace {

TEST(IfcImportTest, ProductsBecomeElementsNamedByGlobalIdInMetresWherePlaced) {
  const Result<std::vector<NamedMesh>> elements = ReadIfcElements(RECONAR_IFC_SAMPLE);
  ASSERT_TRUE(elements.ok()) << elements.status().ToString();
  ASSERT_EQ(elements->size(), 2u);
  const NamedMesh& wall = (*elements)[0];
  const NamedMesh& slab = (*elements)[1];
  EXPECT_EQ(wall.name, "2O2Fr$t4X7Zf8NOew3FLOH Wall east");
  EXPECT_EQ(slab.name, "3bN$1yJ0b5UAuJvVZ2VZdE Floor slab");
  Eigen::AlignedBox3f wall_box, slab_box;
  for (const Eigen::Vector3f& p : wall.mesh.positions) wall_box.extend(p);
  for (const Eigen::Vector3f& p : slab.mesh.positions) slab_box.extend(p);
  EXPECT_TRUE(wall_box.min().isApprox(Eigen::Vector3f(1.0f, 0.0f, 0.0f), 1e-5f)) << wall_box.min().transpose();
  EXPECT_TRUE(wall_box.max().isApprox(Eigen::Vector3f(5.0f, 0.2f, 2.5f), 1e-5f)) << wall_box.max().transpose();
  EXPECT_TRUE(slab_box.max().isApprox(Eigen::Vector3f(6.0f, 5.0f, 0.2f), 1e-5f)) << slab_box.max().transpose();
  EXPECT_EQ(wall.mesh.triangles.size(), 12u);  // a box
  double area = 0.0;
  for (const auto& t : wall.mesh.triangles) {
    area += 0.5 * (wall.mesh.positions[t[1]] - wall.mesh.positions[t[0]])
                      .cross(wall.mesh.positions[t[2]] - wall.mesh.positions[t[0]])
                      .norm();
  }
  EXPECT_NEAR(area, 2 * (4.0 * 0.2 + 4.0 * 2.5 + 0.2 * 2.5), 1e-4);
}

TEST(IfcImportTest, NotIfcIsNamed) {
  const Result<std::vector<NamedMesh>> missing = ReadIfcElements("/nonexistent/design.ifc");
  EXPECT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("/nonexistent/design.ifc"), std::string::npos);
}

}  // namespace
}  // namespace reconar
