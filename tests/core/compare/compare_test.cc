// As built against as planned (core/compare) on a scene with exact truth: a design of a ground and
// four boxes, given in a frame 10 degrees and a metre off the world's, and as-built points sampled
// from what was "built": box a moved 3 cm along its normal, box b never built, box c turned 2
// degrees, box d as designed. Registration by three control points, then the deviation.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/compare/design.h"
#include "core/compare/design_registration.h"
#include "core/compare/deviation.h"
#include "core/math/rigid3.h"
#include "core/sfm/reconstruction.h"
#include "tests/support/design_scene.h"

namespace reconar {
namespace {

constexpr double kDegree = M_PI / 180.0;

using testing::BoxMesh;
using testing::MovedMesh;

void Sample(const Mesh& mesh, double spacing, std::mt19937* random, std::vector<Eigen::Vector3d>* points,
            std::vector<Eigen::Vector3d>* normals) {
  testing::SampleMeshFaces(mesh, spacing, 0.001, random, points, normals);
}

TEST(CompareTest, RegistrationRecoversTheDesignFrameAndEveryChangeIsFound) {
  // The design, in the world frame first.
  Design world_design;
  Mesh ground;
  ground.positions = {{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}};
  ground.triangles = {{0, 1, 2}, {0, 2, 3}};
  world_design.elements.push_back({"ground", ground});
  world_design.elements.push_back({"a", BoxMesh({-2.0, -2.0, 0.0}, {-1.0, -1.2, 1.0})});
  world_design.elements.push_back({"b", BoxMesh({1.0, -2.0, 0.0}, {2.0, -1.0, 0.8})});
  world_design.elements.push_back({"c", BoxMesh({-2.0, 1.0, 0.0}, {-0.8, 2.0, 1.2})});
  world_design.elements.push_back({"d", BoxMesh({1.0, 1.0, 0.0}, {2.2, 2.0, 0.6})});

  // What was built: a moved +3 cm along x (its +x face's normal), b missing, c turned 2 degrees
  // about the vertical through its centre, d and the ground as designed.
  const Rigid3 move_a{Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.03, 0.0, 0.0)};
  const Eigen::Vector3d c_centre(-1.4, 1.5, 0.0);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(2.0 * kDegree, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Rigid3 turn_c{turn, c_centre - turn * c_centre};
  std::mt19937 random(5);
  std::vector<Eigen::Vector3d> points, normals;
  Sample(MovedMesh(world_design.elements[1].mesh, move_a), 0.02, &random, &points, &normals);
  Sample(MovedMesh(world_design.elements[3].mesh, turn_c), 0.02, &random, &points, &normals);
  Sample(world_design.elements[4].mesh, 0.02, &random, &points, &normals);
  {  // the ground, except under what was built
    std::vector<Eigen::Vector3d> ground_points, ground_normals;
    Sample(ground, 0.04, &random, &ground_points, &ground_normals);
    for (size_t i = 0; i < ground_points.size(); ++i) {
      const Eigen::Vector3d& p = ground_points[i];
      const bool under_a = p.x() > -2.0 && p.x() < -0.97 && p.y() > -2.0 && p.y() < -1.2;
      const bool under_c = p.x() > -2.05 && p.x() < -0.75 && p.y() > 0.95 && p.y() < 2.05;
      const bool under_d = p.x() > 1.0 && p.x() < 2.2 && p.y() > 1.0 && p.y() < 2.0;
      if (under_a || under_c || under_d) continue;
      points.push_back(p);
      normals.push_back(ground_normals[i]);
    }
  }

  // The design as delivered: in its own frame, 10 degrees and a metre from the world's.
  const Rigid3 world_from_design_truth{
      Eigen::AngleAxisd(10.0 * kDegree, Eigen::Vector3d(0.2, 0.3, 1.0).normalized()).toRotationMatrix(),
      Eigen::Vector3d(0.6, -0.5, 0.6)};
  ASSERT_NEAR(world_from_design_truth.translation.norm(), 1.0, 0.05);
  Design design;
  for (const NamedMesh& element : world_design.elements) {
    design.elements.push_back({element.name, MovedMesh(element.mesh, world_from_design_truth.Inverse())});
  }
  // Control: three surveyed points on the ground and on d, to a millimetre.
  std::vector<ControlPair> control;
  std::normal_distribution<double> survey(0.0, 0.001);
  for (const Eigen::Vector3d& world : {Eigen::Vector3d(-2.5, 2.5, 0.0), Eigen::Vector3d(2.5, -2.5, 0.0),
                                       Eigen::Vector3d(2.2, 2.0, 0.6), Eigen::Vector3d(2.5, 2.5, 0.0)}) {
    control.push_back({static_cast<int>(control.size()), world_from_design_truth.Inverse() * world,
                       world + Eigen::Vector3d(survey(random), survey(random), survey(random))});
  }

  DesignRegistrationOptions options;
  const Result<DesignRegistration> registration = RegisterDesign(design, control, points, options);
  ASSERT_TRUE(registration.ok()) << registration.status().message();
  EXPECT_EQ(registration->units, "m");
  EXPECT_TRUE(registration->refined);
  const Sim3& fitted = registration->world_from_design;
  const double turn_error =
      Eigen::AngleAxisd(fitted.rotation * world_from_design_truth.rotation.transpose()).angle() / kDegree;
  EXPECT_LT(turn_error, 0.1);
  // Where the scene is, the fitted frame puts the design within 2 mm of its truth.
  for (const Eigen::Vector3d& world : {Eigen::Vector3d(-3, -3, 0), Eigen::Vector3d(3, 3, 1.2), Eigen::Vector3d(3, -3, 0)}) {
    const Eigen::Vector3d design_point = world_from_design_truth.Inverse() * world;
    EXPECT_LT((fitted.Apply(design_point) - world).norm(), 0.002) << world.transpose();
  }
  std::printf("registration: turn error %.4f deg, control RMS %.2f mm, ICP RMS %.2f mm, overlap %.2f\n", turn_error,
              1000 * registration->control_rms_m, 1000 * registration->icp_rms_m, registration->overlap);
  EXPECT_GT(registration->overlap, 0.9);
  EXPECT_LT(registration->icp_rms_m, 0.003);

  DeviationOptions deviation_options;
  deviation_options.tolerance = 0.01;
  const Result<DeviationReport> deviation =
      ComputeDeviation(design, fitted, points, normals, nullptr, deviation_options);
  ASSERT_TRUE(deviation.ok()) << deviation.status().message();
  ASSERT_EQ(deviation->elements.size(), 5u);
  const auto& e = deviation->elements;
  for (const ElementDeviation& element : e) {
    std::printf("%-6s %6d points, mean %6.1f mm, rms %5.1f mm, shift %5.1f mm, turn %.2f deg: %s\n", element.name.c_str(),
                element.points, 1000 * element.mean_m, 1000 * element.rms_m, 1000 * element.shift_m.norm(),
                element.turn_deg, element.verdict.c_str());
  }
  EXPECT_EQ(e[0].verdict, "as_designed") << "ground rms " << e[0].rms_m << " move " << e[0].largest_move_m;
  EXPECT_EQ(e[1].verdict, "deviates");
  EXPECT_NEAR(e[1].shift_m.x(), 0.03, 0.005) << e[1].shift_m.transpose();
  EXPECT_LT(std::hypot(e[1].shift_m.y(), e[1].shift_m.z()), 0.005);
  EXPECT_EQ(e[2].verdict, "missing") << e[2].points << " points";
  EXPECT_EQ(e[3].verdict, "deviates");
  EXPECT_NEAR(e[3].turn_deg, 2.0, 0.2);
  EXPECT_EQ(e[4].verdict, "as_designed") << "d rms " << e[4].rms_m << " move " << e[4].largest_move_m;
  EXPECT_LT(e[4].largest_move_m, 0.005);

  // The same numbers on one thread as on several.
  options.num_threads = 1;
  deviation_options.num_threads = 1;
  const Result<DesignRegistration> one_thread = RegisterDesign(design, control, points, options);
  ASSERT_TRUE(one_thread.ok());
  EXPECT_EQ(one_thread->world_from_design.rotation, fitted.rotation);
  EXPECT_EQ(one_thread->world_from_design.translation, fitted.translation);
  const Result<DeviationReport> one_thread_deviation =
      ComputeDeviation(design, fitted, points, normals, nullptr, deviation_options);
  ASSERT_TRUE(one_thread_deviation.ok());
  EXPECT_EQ(one_thread_deviation->signed_distance_m, deviation->signed_distance_m);
  for (size_t k = 0; k < e.size(); ++k) EXPECT_EQ(one_thread_deviation->elements[k].shift_m, e[k].shift_m);
}

TEST(CompareTest, ControlInMillimetresIsRecognisedAndAStrangeScaleRefused) {
  Design design;
  design.elements.push_back({"box", BoxMesh({0, 0, 0}, {1000, 1000, 1000})});  // millimetres
  std::vector<ControlPair> control;
  for (const Eigen::Vector3d& corner : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1000, 0, 0), Eigen::Vector3d(0, 1000, 0)}) {
    control.push_back({static_cast<int>(control.size()), corner, 0.001 * corner + Eigen::Vector3d(1, 2, 3)});
  }
  DesignRegistrationOptions options;
  options.refine = false;
  const Result<DesignRegistration> mm = RegisterDesign(design, control, {}, options);
  ASSERT_TRUE(mm.ok()) << mm.status().message();
  EXPECT_EQ(mm->units, "mm");
  EXPECT_NEAR(mm->world_from_design.scale, 0.001, 1e-12);
  EXPECT_LT(mm->control_rms_m, 1e-9);
  for (ControlPair& pair : control) pair.world = 0.0005 * pair.design;  // half a millimetre per unit: no unit
  const Result<DesignRegistration> odd = RegisterDesign(design, control, {}, options);
  ASSERT_FALSE(odd.ok());
  EXPECT_NE(odd.status().message().find("--similarity"), std::string::npos);
  options.similarity = true;
  const Result<DesignRegistration> fitted = RegisterDesign(design, control, {}, options);
  ASSERT_TRUE(fitted.ok());
  EXPECT_NEAR(fitted->world_from_design.scale, 0.0005, 1e-12);
  control.resize(2);
  EXPECT_FALSE(RegisterDesign(design, control, {}, options).ok());
}

// Points that the control contradicts (the whole scan 5 cm off what the tags say) do not move the
// design: the ICP's placement would take the control points 5 cm off, and is not taken.
TEST(CompareTest, TheIcpMayNotLeaveTheControl) {
  Design design;
  design.elements.push_back({"box", BoxMesh({0, 0, 0}, {1, 1, 1})});
  std::mt19937 random(9);
  std::vector<Eigen::Vector3d> points, normals;
  Sample(MovedMesh(design.elements[0].mesh, Rigid3{Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.05, 0, 0)}), 0.02,
         &random, &points, &normals);
  std::vector<ControlPair> control;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 1)}) {
    control.push_back({static_cast<int>(control.size()), p, p});
  }
  DesignRegistrationOptions options;
  options.max_distance = 0.1;
  Result<DesignRegistration> registration = RegisterDesign(design, control, points, options);
  ASSERT_TRUE(registration.ok());
  EXPECT_FALSE(registration->refined);
  EXPECT_NE(registration->icp_rejected.find("control points"), std::string::npos) << registration->icp_rejected;
  EXPECT_LT(registration->control_rms_m, 1e-9);
  // Without control the ICP is free to follow the points.
  registration = RegisterDesign(design, {}, points, options);
  ASSERT_TRUE(registration.ok());
  EXPECT_TRUE(registration->refined);
  EXPECT_NEAR(registration->world_from_design.translation.x(), 0.05, 0.002);
}

// A registered photo at `centre` looking at `target`, the world's z up.
SfmImage LookingAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, const std::string& name) {
  SfmImage image;
  image.name = name;
  image.camera_id = 0;
  image.registered = true;
  image.cam_from_world = CamFromWorldLookingAt(centre, target, Eigen::Vector3d::UnitZ());
  return image;
}

// Missing needs the photos to have seen past where the element should stand: a box never built on
// ground the photos saw is missing; a box amid a patch of ground the reconstruction lost, so wide
// that no photo's ray through the box meets a point behind it, is unknown, not missing.
TEST(CompareTest, MissingOnlyWhereThePhotosSawPastIt) {
  Design design;
  design.elements.push_back({"ground", BoxMesh({-3, -3, -0.1}, {3, 3, 0})});
  design.elements.push_back({"never_built", BoxMesh({1.0, 1.0, 0}, {1.4, 1.4, 0.4})});
  design.elements.push_back({"over_a_hole", BoxMesh({-1.2, -1.2, 0}, {-0.8, -0.8, 0.4})});
  std::vector<Eigen::Vector3d> points, normals;
  for (double x = -3; x <= 3; x += 0.02) {
    for (double y = -3; y <= 3; y += 0.02) {
      if (std::hypot(x + 1, y + 1) < 2.0) continue;  // the lost patch
      points.emplace_back(x, y, 0.0);
      normals.emplace_back(0, 0, 1);
    }
  }
  Reconstruction views;
  SfmCamera camera;
  camera.focal = 500;
  camera.cx = 320;
  camera.cy = 240;
  camera.width = 640;
  camera.height = 480;
  camera.k1 = -0.2;
  views.cameras.push_back(camera);
  for (int k = 0; k < 8; ++k) {
    const double angle = 2.0 * M_PI * k / 8;
    views.images.push_back(LookingAt({4.0 * std::cos(angle), 4.0 * std::sin(angle), 2.5}, {0, 0, 0},
                                     "view_" + std::to_string(k)));
  }
  DeviationOptions options;
  const Result<DeviationReport> report = ComputeDeviation(design, Sim3(), points, normals, &views, options);
  ASSERT_TRUE(report.ok()) << report.status().message();
  for (const ElementDeviation& e : report->elements) {
    std::printf("%-12s %7d points, area %.2f m2, seen %.2f m2: %s\n", e.name.c_str(), e.points, e.area_m2,
                e.seen_area_m2, e.verdict.c_str());
  }
  EXPECT_EQ(report->elements[0].verdict, "as_designed");
  EXPECT_EQ(report->elements[1].verdict, "missing");
  EXPECT_EQ(report->elements[2].verdict, "unknown");
  EXPECT_GT(report->elements[1].seen_area_m2, 0.3);  // its top and the sides the ring faces
}

TEST(CompareTest, ControlFileLinesAreCheckedAndNamed) {
  const Result<std::vector<ControlTag>> tags =
      ParseControl("# tags on the north wall\n3 1.0 2.0 0.5\n7 0 0 0  1 0 0  1 1 0  0 1 0  # corners\n", "c.txt");
  ASSERT_TRUE(tags.ok()) << tags.status().message();
  ASSERT_EQ(tags->size(), 2u);
  EXPECT_EQ((*tags)[0].design_points.size(), 1u);
  EXPECT_EQ((*tags)[1].design_points.size(), 4u);
  EXPECT_EQ((*tags)[1].design_points[2], Eigen::Vector3d(1, 1, 0));
  for (const char* bad : {"3 1 2\n", "3 1 2 x\n", "3 1 2 3\n3 4 5 6\n", "# nothing\n", "-1 0 0 0\n"}) {
    const Result<std::vector<ControlTag>> parsed = ParseControl(bad, "c.txt");
    ASSERT_FALSE(parsed.ok()) << bad;
    EXPECT_NE(parsed.status().message().find("c.txt"), std::string::npos) << parsed.status().message();
  }
}

}  // namespace
}  // namespace reconar
