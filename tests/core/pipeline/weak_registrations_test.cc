// The photos a mapping found weak (core/pipeline/weak_registrations.h), from a project's files: a
// photo registered provisionally and the photos sharing its points, a photo left out with a
// verified pair and its partner, less the photos extracted again already.
#include "core/pipeline/weak_registrations.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "core/base/atomic_file.h"
#include "core/sfm/model_io.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

// Photos a, b, c, d, e: a, b, c registered (c provisionally), b and c sharing a point, a and b
// another; d left out but paired with e; e registered; f left out with no pair.
Project MakeProject(const fs::path& root) {
  fs::remove_all(root);
  Project project(root.string());
  Reconstruction model;
  SfmCamera camera;
  camera.width = 640;
  camera.height = 480;
  camera.focal = 500.0;
  model.cameras.push_back(camera);
  for (const char* name : {"a.png", "b.png", "c.png", "d.png", "e.png", "f.png"}) {
    SfmImage image;
    image.name = name;
    image.camera_id = 0;
    image.registered = name[0] != 'd' && name[0] != 'f';
    image.keypoints = {{10.0, 10.0}, {20.0, 20.0}};
    image.point3d_ids = {-1, -1};
    model.images.push_back(image);
  }
  const auto add_point = [&](int first, int second) {
    SfmPoint point;
    point.position = Eigen::Vector3d(0.0, 0.0, 5.0);
    point.track = {{first, 0}, {second, 1}};
    model.images[static_cast<size_t>(first)].point3d_ids[0] = static_cast<int>(model.points.size());
    model.images[static_cast<size_t>(second)].point3d_ids[1] = static_cast<int>(model.points.size());
    model.points.push_back(point);
  };
  add_point(0, 1);  // a, b
  add_point(1, 2);  // b, c
  EXPECT_TRUE(CreateDirectories(project.SparseDir()).ok());
  EXPECT_TRUE(WriteColmapTextModel(model, project.SparseDir()).ok());
  EXPECT_TRUE(WriteFileAtomically(project.SparseDir() + "/report.json",
                                  R"({"provisional": [{"image": "c.png", "evidence": "few inliers", "inliers": 17, "kept": true},
                                                      {"image": "e.png", "evidence": "neighbour", "inliers": 6, "kept": false}],
                                      "unregistered": [{"image": "d.png", "reason": "sees only 4 reconstructed points"},
                                                       {"image": "f.png", "reason": "no verified matches to other images"}]})")
                  .ok());
  EXPECT_TRUE(CreateDirectories(project.MatchesDir()).ok());
  const char* identity = " verified 1 1 0 0 0 1 0 0 0 1\n0 1\n";
  EXPECT_TRUE(WriteFileAtomically(project.MatchesPath(), std::string("# reconar matches v1\n") + "pair a.png b.png" +
                                                             identity + "pair b.png c.png" + identity +
                                                             "pair d.png e.png" + identity)
                  .ok());
  return project;
}

TEST(WeakRegistrationsTest, AProvisionalPhotoAndOneLeftOutBringTheirPartners) {
  const fs::path root = fs::temp_directory_path() / ("reconar_weak_" + std::to_string(::getpid()));
  const Project project = MakeProject(root);
  const auto weak = WeaklyRegisteredPhotos(project);
  ASSERT_TRUE(weak.ok()) << weak.status().ToString();
  ASSERT_EQ(weak->size(), 4u);  // c, its point partner b, d, its pair partner e; not a, not f
  EXPECT_NE(weak->at("c.png").find("registered provisionally (few inliers, 17 points)"), std::string::npos);
  EXPECT_NE(weak->at("b.png").find("sees points with c.png"), std::string::npos);
  EXPECT_NE(weak->at("d.png").find("not registered: sees only 4"), std::string::npos);
  EXPECT_NE(weak->at("e.png").find("paired with d.png"), std::string::npos);

  // Photos extracted again already are left out; the recorded request is read back.
  ASSERT_TRUE(WriteFileAtomically(project.MatchesDir() + "/report.json",
                                  R"({"reextracted": [{"image": "b.png"}], "extract_again": [{"image": "c.png", "reason": "why"}]})")
                  .ok());
  const auto again = WeaklyRegisteredPhotos(project);
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_EQ(again->count("b.png"), 0u);
  EXPECT_EQ(again->size(), 3u);
  const std::map<std::string, std::string> recorded = RecordedExtractAgain(project);
  ASSERT_EQ(recorded.size(), 1u);
  EXPECT_EQ(recorded.at("c.png"), "why");
  fs::remove_all(root);
}

TEST(WeakRegistrationsTest, AProjectWithoutAMappingIsAnError) {
  const fs::path root = fs::temp_directory_path() / ("reconar_weak_none_" + std::to_string(::getpid()));
  fs::remove_all(root);
  EXPECT_FALSE(WeaklyRegisteredPhotos(Project(root.string())).ok());
  EXPECT_TRUE(RecordedExtractAgain(Project(root.string())).empty());
}

}  // namespace
}  // namespace reconar
